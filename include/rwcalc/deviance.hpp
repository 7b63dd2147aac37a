#pragma once
#ifndef RWCALC_USES_NUMERICS
#error "rwcalc/deviance.hpp belongs to the numerics layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file deviance.hpp
/// A variance estimate with ν degrees of freedom (model·χ²_ν/ν, a Gamma law of shape ν/2): its
/// Gamma deviance against its model (what the fit minimises and the misfit figures report), and the
/// bias of its square root (what a noise coefficient, the root of a fitted variance, inherits).

namespace rwcalc {

/// ν(x − 1 − ln x), x = observed/model > 0: about ν(x − 1)²/2 near x = 1.
double gamma_deviance(double observed, double model, double nu);
/// The deviance's square root with the sign of observed − model (≈ a standard normal deviate under
/// the model); 0 unless observed, model and ν are > 0.
double deviance_residual(double observed, double model, double nu);
/// Its mean for observed/model ~ χ²_ν/ν: −ν(ψ(ν/2) − ln(ν/2)) = 1 + 1/(3ν) + O(ν⁻³) (the Bartlett
/// factor: deviances divided by it sum to ≈ χ² at small ν).
double gamma_deviance_mean(double nu);
/// E[√(χ²_ν/ν)] = √(2/ν)·Γ((ν+1)/2)/Γ(ν/2) = 1 − 1/(4ν) + O(ν⁻²): the square root of an unbiased
/// variance estimate is low by this factor (0.921 at ν = 3, 0.975 at ν = 10); 1 for ν = ∞.
double chi_root_mean(double nu);
/// The fewest degrees of freedom whose root bias mean_unbiased_root takes out. An estimate that is
/// a positive combination of squared Gaussian deviates (an AV, a fitted c where the data fix it) has
/// Satterthwaite's ν = (Σλ)²/Σλ² ≥ 1; a smaller ν says the estimate is mostly noise about its bound
/// at 0, where the χ² law and its root's factor (which grows without bound: 1/0.27 at ν = 0.05) do
/// not apply.
inline constexpr double kRootMinEdf = 1.0;
/// √v / chi_root_mean(ν) with ν = 2v²/var_v (a Gamma law's degrees of freedom from its mean and
/// variance): the root of an unbiased estimate v ≥ 0 with its bias taken out where ν ≥ kRootMinEdf
/// (at most 1/0.798 = +25 %); the plain √v below that and where var_v ≤ 0.
double mean_unbiased_root(double v, double var_v);
/// The same with ν = 2·level²/var_v: the EDF read at `level`, an estimate of the same variance less
/// noisy than v itself. With v in its place the factor follows v's own noise (largest where v is low
/// by chance) and under-corrects: a 30-min record's sign-free B² (relative scatter 0.64) comes out
/// 2.5 % low, read at the bounded fit's B² 1.9 % (docs/term-choice.md).
double mean_unbiased_root(double v, double var_v, double level);

}  // namespace rwcalc
