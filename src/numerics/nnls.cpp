// Non-negative least squares over every support (nnls.hpp).
#include "rwcalc/nnls.hpp"

#include <vector>

namespace rwcalc {

NnlsFit nnls(const Eigen::MatrixXd& g, const Eigen::VectorXd& y, const Eigen::VectorXd& w, unsigned free,
             unsigned signed_cols) {
  const Eigen::MatrixXd gw = g.array().colwise() * w.array();
  const Eigen::MatrixXd a = g.transpose() * gw;
  const Eigen::VectorXd b = gw.transpose() * y;
  NnlsFit fit{Eigen::VectorXd::Zero(g.cols()), 0.0};
  double best = 0;  // the objective less yᵀWy: 0 on the empty support
  free &= (1u << g.cols()) - 1;
  signed_cols &= free;
  for (unsigned s = free; s != 0; s = (s - 1) & free) {
    if ((s & signed_cols) != signed_cols) continue;
    std::vector<Eigen::Index> ids;
    for (Eigen::Index i = 0; i < g.cols(); ++i)
      if (s & (1u << i)) ids.push_back(i);
    if (!(a.diagonal()(ids).array() > 0).all()) continue;
    const Eigen::VectorXd scale = a.diagonal()(ids).cwiseSqrt().cwiseInverse();
    const Eigen::LLT<Eigen::MatrixXd> llt(scale.asDiagonal() * a(ids, ids) * scale.asDiagonal());
    if (llt.info() != Eigen::Success || llt.rcond() < 1e-13) continue;
    const Eigen::VectorXd bs = b(ids).cwiseProduct(scale), z = llt.solve(bs), x = z.cwiseProduct(scale);
    bool positive = true;  // on the columns held to x ≥ 0
    for (std::size_t k = 0; k < ids.size(); ++k)
      positive = positive && (x[static_cast<Eigen::Index>(k)] > 0 || ((signed_cols >> ids[k]) & 1u));
    if (!x.allFinite() || !positive || !(-bs.dot(z) < best)) continue;
    best = -bs.dot(z);
    fit.x.setZero();
    fit.x(ids) = x;
  }
  fit.chi2 = ((y - g * fit.x).array().square() * w.array()).sum();
  return fit;
}

}  // namespace rwcalc
