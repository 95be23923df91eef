#include <arm_neon.h>

#include "bench/fma_loop.h"

namespace ampi::bench::neon {

float fma_loop(int64_t iterations, float start) {
  float32x4_t acc[kFmaChains];
  for (int j = 0; j < kFmaChains; ++j) acc[j] = vdupq_n_f32(start + 0.01f * j);
  const float32x4_t mul = vdupq_n_f32(kFmaMul), add = vdupq_n_f32(kFmaAdd);
  for (int64_t i = 0; i < iterations; ++i)
    for (int j = 0; j < kFmaChains; ++j) acc[j] = vfmaq_f32(add, acc[j], mul);
  for (int j = 1; j < kFmaChains; ++j) acc[0] = vaddq_f32(acc[0], acc[j]);
  return vaddvq_f32(acc[0]);
}

}  // namespace ampi::bench::neon
