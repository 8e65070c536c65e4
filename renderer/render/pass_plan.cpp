#include "renderer/render/pass_plan.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

int PassPlan::next(int done, double seconds_per_sample) const {
  const int left = spp - done;
  if (left <= 0) return 0;
  if (done == 0) return std::min(std::max(1, first), left);
  // Doubling: the samples so far again (first, first, 2 first, 4 first, ... from the start).
  int n = std::max(std::max(1, first), done);
  if (done < fixed_from) {
    if (min_seconds > 0 && seconds_per_sample > 0) {
      const double wanted = std::ceil(min_seconds / seconds_per_sample);
      if (wanted > double(n)) n = wanted >= double(left) ? left : int(wanted);
    }
    // Up to the first fixed boundary, not past it.
    if (fixed_from != INT_MAX) n = std::min(n, fixed_from - done);
  }
  return std::min(n, left);
}

}  // namespace penumbra
