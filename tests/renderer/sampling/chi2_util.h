#pragma once
// Pearson's chi-square goodness of fit of observed counts against expected counts, with cells of
// low expectation pooled (pbrt-v4 and Mitsuba 3's chi2 tests do the same); shared by the
// distribution and environment-map sampling tests.
#include <sstream>
#include <string>
#include <vector>

#include "tests/renderer/materials/bsdf_test_util.h"

namespace penumbra::test {

struct Chi2Outcome {
  bool pass = false;
  double p_value = 0.0;
  std::string message;
};

// Cells expecting less than `min_expected` are pooled into one. A cell expecting nothing that
// received samples fails outright (sampling outside the density's support).
inline Chi2Outcome chi2_goodness_of_fit(const std::vector<double>& observed,
                                        const std::vector<double>& expected,
                                        double significance = 0.01, double min_expected = 5.0) {
  Chi2Outcome out;
  std::ostringstream msg;
  double chi2 = 0.0, pooled_obs = 0.0, pooled_exp = 0.0;
  int cells = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] <= 0.0 && observed[i] > 0.0) {
      msg << "cell " << i << " observed " << observed[i] << " samples but expects none";
      out.message = msg.str();
      return out;
    }
    if (expected[i] < min_expected) {
      pooled_obs += observed[i];
      pooled_exp += expected[i];
    } else {
      const double d = observed[i] - expected[i];
      chi2 += d * d / expected[i];
      ++cells;
    }
  }
  if (pooled_exp > 0.0) {
    const double d = pooled_obs - pooled_exp;
    chi2 += d * d / pooled_exp;
    ++cells;
  }
  const int dof = cells - 1;
  out.p_value = dof > 0 ? gamma_q(0.5 * dof, 0.5 * chi2) : 1.0;
  out.pass = out.p_value >= significance;
  msg << "chi2 = " << chi2 << ", dof = " << dof << ", p = " << out.p_value;
  out.message = msg.str();
  return out;
}

}  // namespace penumbra::test
