#include "kernels/x86/avx512_kernels.h"
#include "kernels/x86/avx512_math.h"

namespace ampi::avx512 {

static __mmask16 tail_mask(int64_t left) {
  return left >= 16 ? static_cast<__mmask16>(0xffff) : static_cast<__mmask16>((1u << left) - 1u);
}

void add(const float* a, const float* b, int64_t n, ActivationSpec act, float* out) {
  for (int64_t i = 0; i < n; i += 16) {
    const __mmask16 m = tail_mask(n - i);
    const __m512 s = _mm512_add_ps(_mm512_maskz_loadu_ps(m, a + i), _mm512_maskz_loadu_ps(m, b + i));
    _mm512_mask_storeu_ps(out + i, m, activate(s, act));
  }
}

void activate(float* x, int64_t n, ActivationSpec act) {
  for (int64_t i = 0; i < n; i += 16) {
    const __mmask16 m = tail_mask(n - i);
    _mm512_mask_storeu_ps(x + i, m, activate(_mm512_maskz_loadu_ps(m, x + i), act));
  }
}

}  // namespace ampi::avx512
