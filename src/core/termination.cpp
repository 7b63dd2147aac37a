#include "rwcalc/termination.hpp"

#include <nlohmann/json.hpp>

namespace rwcalc {

namespace {

// Severity for combine: a limit hit says more than a stall, a stall more than convergence.
int severity(TerminationStatus s) noexcept {
  switch (s) {
    case TerminationStatus::IterationLimit: return 2;
    case TerminationStatus::NoProgress: return 1;
    case TerminationStatus::Converged: break;
  }
  return 0;
}

}  // namespace

Termination combine(const Termination& a, const Termination& b) noexcept {
  return {severity(b.status) > severity(a.status) ? b.status : a.status, a.iterations + b.iterations};
}

std::string_view to_string(TerminationStatus s) noexcept {
  switch (s) {
    case TerminationStatus::IterationLimit: return "iteration_limit";
    case TerminationStatus::NoProgress: return "no_progress";
    case TerminationStatus::Converged: break;
  }
  return "converged";
}

nlohmann::json to_json(const Termination& t) { return {{"status", to_string(t.status)}, {"iterations", t.iterations}}; }

}  // namespace rwcalc
