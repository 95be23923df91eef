#include "kernels/arm/neon_kernels.h"
#include "kernels/arm/neon_math.h"

namespace ampi::neon {

void add(const float* a, const float* b, int64_t n, ActivationSpec act, float* out) {
  int64_t i = 0;
  for (; i + 4 <= n; i += 4) vst1q_f32(out + i, activate(vaddq_f32(vld1q_f32(a + i), vld1q_f32(b + i)), act));
  for (; i < n; ++i) out[i] = ampi::activate(a[i] + b[i], act);
}

void activate(float* x, int64_t n, ActivationSpec act) {
  int64_t i = 0;
  for (; i + 4 <= n; i += 4) vst1q_f32(x + i, activate(vld1q_f32(x + i), act));
  for (; i < n; ++i) x[i] = ampi::activate(x[i], act);
}

}  // namespace ampi::neon
