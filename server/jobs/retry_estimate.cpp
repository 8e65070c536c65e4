#include "server/jobs/retry_estimate.h"

#include <algorithm>
#include <limits>

namespace penumbra::server {

double queue_retry_after_seconds(const std::vector<RunningJobEstimate>& running,
                                 double average_job_seconds, int workers) {
  double soonest = std::numeric_limits<double>::infinity();
  for (const RunningJobEstimate& r : running)
    if (r.fraction > 0 && r.eta_seconds >= 0) soonest = std::min(soonest, r.eta_seconds);
  double wait = 1.0;
  if (soonest < std::numeric_limits<double>::infinity())
    wait = soonest;
  else if (average_job_seconds > 0)
    wait = average_job_seconds / std::max(1, workers);
  return std::clamp(wait, 1.0, 3600.0);
}

}  // namespace penumbra::server
