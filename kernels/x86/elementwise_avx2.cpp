#include "kernels/x86/avx2_kernels.h"
#include "kernels/x86/avx2_math.h"

namespace ampi::avx2 {

void add(const float* a, const float* b, int64_t n, ActivationSpec act, float* out) {
  int64_t i = 0;
  for (; i + 8 <= n; i += 8)
    _mm256_storeu_ps(out + i, activate(_mm256_add_ps(_mm256_loadu_ps(a + i), _mm256_loadu_ps(b + i)), act));
  for (; i < n; ++i) out[i] = ampi::activate(a[i] + b[i], act);
}

void activate(float* x, int64_t n, ActivationSpec act) {
  int64_t i = 0;
  for (; i + 8 <= n; i += 8) _mm256_storeu_ps(x + i, activate(_mm256_loadu_ps(x + i), act));
  for (; i < n; ++i) x[i] = ampi::activate(x[i], act);
}

}  // namespace ampi::avx2
