#pragma once
// Retry-After for a full queue (429): when a place is likely to free. A place frees when a worker
// takes the next queued job, i.e. when the first running job ends, so the estimate is the
// shortest remaining time among running renders (their own ETA from progress), else the observed
// average job time divided by the workers. With neither (nothing has run yet) it is 1 s: an
// unknown wait is retried soon, never guessed as a fixed time per queued job (issue 15: 320 s for
// a queue of 0.02 s jobs).
#include <optional>
#include <vector>

namespace penumbra::server {

struct RunningJobEstimate {
  double fraction = 0;     // 0..1 done
  double eta_seconds = 0;  // the renderer's estimate of the time left
};

double queue_retry_after_seconds(const std::vector<RunningJobEstimate>& running,
                                 double average_job_seconds, int workers);

}  // namespace penumbra::server
