// Non-negative least squares over every support (nnls.hpp).
#include "rwcalc/nnls.hpp"

#include <vector>

namespace rwcalc {

NnlsFit nnls(const Eigen::MatrixXd& g, const Eigen::VectorXd& y, const Eigen::VectorXd& w, unsigned free) {
  const Eigen::MatrixXd gw = g.array().colwise() * w.array();
  const Eigen::MatrixXd a = g.transpose() * gw;
  const Eigen::VectorXd b = gw.transpose() * y;
  NnlsFit fit{Eigen::VectorXd::Zero(g.cols()), 0.0};
  double best = 0;  // the objective less yᵀWy: 0 on the empty support
  free &= (1u << g.cols()) - 1;
  for (unsigned s = free; s != 0; s = (s - 1) & free) {
    std::vector<Eigen::Index> ids;
    for (Eigen::Index i = 0; i < g.cols(); ++i)
      if (s & (1u << i)) ids.push_back(i);
    if (!(a.diagonal()(ids).array() > 0).all()) continue;
    const Eigen::VectorXd scale = a.diagonal()(ids).cwiseSqrt().cwiseInverse();
    const Eigen::LLT<Eigen::MatrixXd> llt(scale.asDiagonal() * a(ids, ids) * scale.asDiagonal());
    if (llt.info() != Eigen::Success || llt.rcond() < 1e-13) continue;
    const Eigen::VectorXd bs = b(ids).cwiseProduct(scale), z = llt.solve(bs), x = z.cwiseProduct(scale);
    if (!x.allFinite() || (x.array() <= 0).any() || !(-bs.dot(z) < best)) continue;
    best = -bs.dot(z);
    fit.x.setZero();
    fit.x(ids) = x;
  }
  fit.chi2 = ((y - g * fit.x).array().square() * w.array()).sum();
  return fit;
}

}  // namespace rwcalc
