// The constants of the vector exp functions and of GELU's erfc, shared by the scalar
// reference (kernels/activation.h) and every ISA's math header (x86/avx2_math.h,
// x86/avx512_math.h, arm/neon_math.h) so all evaluate the same polynomials. Coefficients
// are listed highest degree first, for Horner's rule.
#pragma once
#include <cstddef>

namespace ampi::exp_poly {

// exp: the Cephes single-precision polynomial. x is clamped to [kMin, kMax],
// n = round(x * kLog2e), r = x - n ln2 with ln2 split in two (kLn2Hi + kLn2Lo) so r stays
// exact, e^r = 1 + r + r^2 P(r); e^x = 2^n e^r. Relative error about 2e-7.
constexpr float kMin = -87.3f, kMax = 88.3f;
constexpr float kLog2e = 1.44269504088896341f;
constexpr float kLn2Hi = 0.693359375f, kLn2Lo = -2.12194440e-4f;
constexpr float kExp[] = {1.9875691500e-4f, 1.3981999507e-3f, 8.3334519073e-3f,
                          4.1665795894e-2f, 1.6666665459e-1f, 5.0000001201e-1f};

// exp2_nonpositive: 2^y for y in [kExp2Min, 0] as 2^n times the degree-6 Taylor
// polynomial of 2^f on f = y - n in [-0.5, 0.5]. Relative error about 1e-7.
constexpr float kExp2Min = -126.0f;
constexpr float kExp2[] = {1.540353039e-4f, 1.333355815e-3f, 9.618129108e-3f, 5.550410866e-2f,
                           2.402265070e-1f, 6.931471806e-1f, 1.0f};

}  // namespace ampi::exp_poly

namespace ampi::erfc_poly {

// GELU's tail: h(u) = erfc(u / sqrt 2) / 2 = Phi(-u) for u = |x| >= 0, written as
// exp(-u^2 / 2) * Q(u) with Q(u) = h(u) exp(u^2 / 2) smooth and slowly varying (it falls
// from 1/2 like 1 / (u sqrt(2 pi))), so a polynomial fits it without a division.
// Q is a degree-12 polynomial in t = u - kCentre, fitted on u in [0, kMaxArg] to minimise
// the error of h itself (the fit weighs Q's error by exp(-u^2 / 2));
// scripts/fit_gelu_erfc.py reproduces these float32 coefficients. Centring keeps every
// term small against Q (no cancellation), so ISAs that fuse the multiply-adds differently
// still agree within a few ulp even where h is tiny. The fit's h is within 4.4e-9 of
// the exact one in exact arithmetic; evaluated in float without FMA, h is within 8e-8.
// With the exponential's error and the final roundings, gelu(x) = x Phi(x) has Phi within
// 1.4e-7 of the exact normal CDF (1.34e-7 measured on [-12, 12] in steps of 2^-16, the
// reference and the x86 ISAs, with the base-2 exponential below), most of it float
// rounding where Phi is near 1/2.
// Beyond kMaxArg, Q is held at Q(kMaxArg): h there is below 1e-8 and exp(-u^2 / 2) takes
// it to 0. Beyond kZeroArg, h < 1e-38 is taken as 0: the exponential's floor (2^-126)
// would otherwise hold it at about 1e-39, which the final x * h scales back up for huge x.
constexpr float kMaxArg = 5.65f;
constexpr float kCentre = 2.825f;
constexpr float kZeroArg = 13.0f;
// exp(-u^2 / 2) = 2^(u^2 * kMinusHalfLog2e): the base-2 exponential takes fewer steps
// (the GELU epilogue of ViT-S's fc1, 1370 x 1536 outputs, 1 thread, AVX-512: 0.95 ->
// 0.8 ms). Up to kZeroArg the exponent stays above exp2's floor of -126.
constexpr float kMinusHalfLog2e = -0.721347520444481703680f;
constexpr float kQ[] = {5.854037610220075e-08f,   3.8070660934863554e-07f, 8.903546131477924e-07f,
                        -1.3927290183346486e-06f, -4.8367005547333974e-06f, -1.5344472558354028e-05f,
                        4.359320519142784e-05f,   -0.00014518068928737193f, 0.0006902930908836424f,
                        -0.00274845608510077f,    0.010473871603608131f,    -0.03783039376139641f,
                        0.12782754004001617f};

}  // namespace ampi::erfc_poly
