#include <immintrin.h>

#include "bench/fma_loop.h"

namespace ampi::bench::avx512 {

float fma_loop(int64_t iterations, float start) {
  __m512 acc[kFmaChains];
  for (int j = 0; j < kFmaChains; ++j) acc[j] = _mm512_set1_ps(start + 0.01f * j);
  const __m512 mul = _mm512_set1_ps(kFmaMul), add = _mm512_set1_ps(kFmaAdd);
  for (int64_t i = 0; i < iterations; ++i)
    for (int j = 0; j < kFmaChains; ++j) acc[j] = _mm512_fmadd_ps(acc[j], mul, add);
  for (int j = 1; j < kFmaChains; ++j) acc[0] = _mm512_add_ps(acc[0], acc[j]);
  alignas(64) float lanes[16];
  _mm512_store_ps(lanes, acc[0]);
  float sum = 0.0f;  // a plain loop: no std:: template is instantiated with these flags
  for (float lane : lanes) sum += lane;
  return sum;
}

}  // namespace ampi::bench::avx512
