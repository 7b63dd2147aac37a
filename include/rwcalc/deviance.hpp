#pragma once
#ifndef RWCALC_USES_NUMERICS
#error "rwcalc/deviance.hpp belongs to the numerics layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file deviance.hpp
/// The Gamma deviance of a variance estimate with ν degrees of freedom (model·χ²_ν/ν, a Gamma law
/// of shape ν/2) against its model: what the fit minimises and the misfit figures report.

namespace rwcalc {

/// ν(x − 1 − ln x), x = observed/model > 0: about ν(x − 1)²/2 near x = 1.
double gamma_deviance(double observed, double model, double nu);
/// The deviance's square root with the sign of observed − model (≈ a standard normal deviate under
/// the model); 0 unless observed, model and ν are > 0.
double deviance_residual(double observed, double model, double nu);
/// Its mean for observed/model ~ χ²_ν/ν: −ν(ψ(ν/2) − ln(ν/2)) = 1 + 1/(3ν) + O(ν⁻³) (the Bartlett
/// factor: deviances divided by it sum to ≈ χ² at small ν).
double gamma_deviance_mean(double nu);

}  // namespace rwcalc
