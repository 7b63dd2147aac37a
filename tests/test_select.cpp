// detail::select_nonnegative: the k-th smallest of values spread over several arrays, against
// std::nth_element over their concatenation — continuous and quantised values (many equal), zeros,
// subnormals and infinities, values all in one bucket, empty arrays and every rank of small sets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <span>
#include <vector>

#include "io/select.hpp"

namespace {

using rwcalc::detail::select_nonnegative;

double by_nth_element(std::vector<std::vector<double>> parts, std::size_t k) {
  std::vector<double> all;
  for (const auto& p : parts) all.insert(all.end(), p.begin(), p.end());
  std::nth_element(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(k), all.end());
  return all[k];
}

double selected(const std::vector<std::vector<double>>& parts, std::size_t k) {
  std::vector<std::span<const double>> sets;
  for (const auto& p : parts) sets.emplace_back(p);
  return select_nonnegative(sets, k);
}

std::size_t total(const std::vector<std::vector<double>>& parts) {
  std::size_t n = 0;
  for (const auto& p : parts) n += p.size();
  return n;
}

// Split v at random points into `count` arrays (some of them empty).
std::vector<std::vector<double>> split(const std::vector<double>& v, int count, std::mt19937_64& rng) {
  std::vector<std::size_t> cut{0, v.size()};
  std::uniform_int_distribution<std::size_t> at(0, v.size());
  for (int i = 1; i < count; ++i) cut.push_back(at(rng));
  std::sort(cut.begin(), cut.end());
  std::vector<std::vector<double>> parts;
  for (std::size_t i = 0; i + 1 < cut.size(); ++i) parts.emplace_back(v.begin() + cut[i], v.begin() + cut[i + 1]);
  return parts;
}

TEST(SelectNonnegative, MatchesNthElementOnContinuousAndQuantisedValues) {
  std::mt19937_64 rng(20261124);
  std::normal_distribution<double> gauss(0.0, 3.7);
  std::uniform_int_distribution<int> pulses(-3, 3);
  for (int trial = 0; trial < 40; ++trial) {
    const std::size_t n = 1 + rng() % 50000;
    std::vector<double> v(n);
    for (auto& x : v) x = trial % 2 ? std::abs(gauss(rng)) : std::abs(0.5 * pulses(rng)) * 331.2;  // quantised: 7 values
    const auto parts = split(v, 1 + trial % 9, rng);
    for (std::size_t k : {std::size_t{0}, n / 2, n / 3, n - 1}) EXPECT_EQ(selected(parts, k), by_nth_element(parts, k)) << trial;
  }
}

TEST(SelectNonnegative, EveryRankOfSmallSetsWithTiesZerosAndExtremes) {
  const double tiny = std::numeric_limits<double>::denorm_min();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<std::vector<std::vector<double>>> cases{
      {{5.0}},
      {{0.0, 0.0, 0.0}, {}, {0.0}},
      {{}, {2.0, 1.0}, {}, {1.0, 2.0, 1.5}},
      {{1.0, 1.0 + 1e-15, 1.0 + 2e-15}, {1.0 + 3e-15}},  // one bucket: ordered within it
      {{tiny, 0.0, 4 * tiny}, {inf, 1e308, 1e-308}, {3.0}},
      {{7.0, 7.0, 7.0, 7.0}, {7.0, 6.0}},
  };
  for (const auto& c : cases)
    for (std::size_t k = 0; k < total(c); ++k) EXPECT_EQ(selected(c, k), by_nth_element(c, k)) << "rank " << k;
}

TEST(SelectNonnegative, AllValuesInTheBucketOfTheRank) {
  // 2e5 values within one bucket (the same top 16 bits), as a record quantised to a single
  // residual would give: the rank is found by ordering that bucket.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(1.0, 1.0 + 1.0 / 32);
  std::vector<double> v(200000);
  for (auto& x : v) x = u(rng);
  const auto parts = split(v, 4, rng);
  EXPECT_EQ(selected(parts, v.size() / 2), by_nth_element(parts, v.size() / 2));
}

}  // namespace
