#pragma once
// What noise alone puts into a convergence rung's relMSE against a reference, and the standard
// error of the excess over it (lucent::ConvergePoint's noise_relmse and excess_standard_error).
#include "lucent/render.hpp"

namespace lucent::converge_detail {

/// The relMSE explained by noise: sum over pixel-channels of the variances of both means,
/// weighted as relMSE weights squared errors. 0 when `a` has no variance estimate (most of its
/// pixels of fewer than 2 samples).
double noise_relmse(const RenderResult& a, const RenderResult& ref);

/// ConvergePoint::excess_standard_error of render `a` against `ref`: the standard error of
/// relMSE - noise_relmse where `a` is unbiased, from the spread of the pixels' terms (0 where
/// noise_relmse has no variance estimate).
double excess_standard_error(const RenderResult& a, const RenderResult& ref);

}  // namespace lucent::converge_detail
