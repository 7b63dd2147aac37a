// The names of the diagnosis's effects in the output, and a finding's parameters by name.
#include <array>
#include <stdexcept>
#include <string>

#include "rwcalc/diagnose.hpp"

namespace rwcalc {

namespace {

struct EffectNames {
  std::string_view detector, finding;
};
/// A line above the slow band is reported under its own detector name, as a "sinusoid".
constexpr std::array<EffectNames, kEffectCount> kNames{{
    {"sinusoid", "sinusoid"},
    {"sinusoid_hf", "sinusoid"},
    {"bias_step", "bias_step"},
    {"warmup_transient", "warmup_transient"},
    {"gauss_markov", "gauss_markov"},
    {"lowpass", "lowpass"},
}};

}  // namespace

std::string_view detector_name(Effect e) { return kNames[static_cast<std::size_t>(e)].detector; }
std::string_view finding_name(Effect e) { return kNames[static_cast<std::size_t>(e)].finding; }

const FindingParameter& Finding::parameter(std::string_view name) const {
  for (const auto& p : parameters)
    if (p.name == name) return p;
  throw std::out_of_range("a " + std::string(finding_name(effect)) + " finding has no parameter " + std::string(name));
}

}  // namespace rwcalc
