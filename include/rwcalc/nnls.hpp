#pragma once
#ifndef RWCALC_USES_NUMERICS
#error "rwcalc/nnls.hpp belongs to the numerics layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file nnls.hpp
/// Non-negative weighted least squares for a few columns (a model's noise terms).
#include <Eigen/Dense>

namespace rwcalc {

struct NnlsFit {
  Eigen::VectorXd x;  ///< ≥ 0 on the free columns (any sign on the signed ones), 0 on the others
  double chi2 = 0;    ///< Σ w (y − G x)²
};

/// min Σ w (y − G x)² over x_i ≥ 0 for the columns i in `free` (bit i, i < 16), the other x_i = 0;
/// the columns in `signed_cols` (a subset of `free`) may take either sign. Exact: the optimum solves
/// its own support unconstrained, so every support holding the signed columns is solved (Jacobi-
/// scaled Cholesky of the normal equations) and the best non-singular one positive on its other
/// columns kept.
NnlsFit nnls(const Eigen::MatrixXd& g, const Eigen::VectorXd& y, const Eigen::VectorXd& w, unsigned free,
             unsigned signed_cols = 0);

}  // namespace rwcalc
