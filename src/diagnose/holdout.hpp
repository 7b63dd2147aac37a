#pragma once
/// @file holdout.hpp
/// The out-of-sample check of the diagnosis: the record cut into blocks, each model fitted on one
/// block and scored on predicting a neighbouring one (docs/diagnosis.md, Gain).
#include <vector>

#include "diagnose/detector.hpp"

namespace rwcalc::diag {

/// s, the shortest record the diagnosis takes (its detectors need it); blocks of thirds are used
/// when each lasts as long.
constexpr double kMinDuration = 1200.0;

/// The effects named on the whole record and what they tell the blocks.
struct Named {
  std::vector<const Detector*> detectors;  ///< in naming order (Effect)
  double sin_hint_hz = 0;   ///< frequency of a named sinusoid
  double line_hint_hz = 0;  ///< frequency of a named coherent high-frequency line
};

/// Mean per-point prediction deviance of the base and the extended model over the folds.
struct HoldoutScores {
  double base = 0, extended = 0;
};
/// `full`: the whole record as a stretch; `r`: the diagnosis so far (settings, extended model,
/// ensemble sizes).
HoldoutScores out_of_sample(const Stretch& full, const DiagnoseResult& r, const Named& named);

}  // namespace rwcalc::diag
