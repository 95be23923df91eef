// The constants of the vector exp functions, shared by every ISA's math header
// (x86/avx2_math.h, x86/avx512_math.h, arm/neon_math.h) so the three evaluate the same
// polynomials. Coefficients are listed highest degree first, for Horner's rule.
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
