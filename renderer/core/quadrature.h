#pragma once
// Numerical quadrature rules shared by the precomputed BSDF tables.
#include <vector>

namespace penumbra {

// Gauss-Legendre nodes and weights on [-1, 1] (Newton iteration on P_n; Golub-Welsch would do too).
void gauss_legendre(int n, std::vector<double>& nodes, std::vector<double>& weights);

}  // namespace penumbra
