#include "rwcalc/sample_variance.hpp"

namespace rwcalc {

double sample_variance(std::span<const double> v) {
  double mean = 0;
  for (const double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double ss = 0;
  for (const double x : v) ss += (x - mean) * (x - mean);
  return ss / static_cast<double>(v.size() - 1);
}

}  // namespace rwcalc
