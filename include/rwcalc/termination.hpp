#pragma once
/// @file termination.hpp
/// How an iterative computation stopped, carried in its result (as Ceres' Summary carries its
/// termination type): a result whose iteration ended before its convergence test held says so.
#include <string_view>

#include <nlohmann/json_fwd.hpp>

namespace rwcalc {

enum class TerminationStatus {
  Converged,       ///< the computation's convergence test held
  IterationLimit,  ///< it took its most iterations before the test held
  NoProgress,      ///< no step improved the objective while the test did not yet hold
};

struct Termination {
  TerminationStatus status = TerminationStatus::Converged;
  int iterations = 0;  ///< iterations taken (over every stage the result combines)
  [[nodiscard]] bool converged() const noexcept { return status == TerminationStatus::Converged; }
};

/// Two stages of one result: the worse status (iteration limit, then no progress, then converged)
/// and the iterations of both.
[[nodiscard]] Termination combine(const Termination& a, const Termination& b) noexcept;

/// "converged", "iteration_limit", "no_progress" (the JSON's words; never translated).
[[nodiscard]] std::string_view to_string(TerminationStatus s) noexcept;

/// The JSON object {"status": to_string(status), "iterations": n}.
[[nodiscard]] nlohmann::json to_json(const Termination& t);

}  // namespace rwcalc
