// AVX-512 transformer row kernels (contracts in kernels/kernel_list.def): as the AVX2
// ones, 16 floats a vector, whole vectors through plain loads and stores, the tail
// through mask registers.
#include <cmath>

// GCC 12 warns that the _mm512_undefined_ps() inside its own reduction and max intrinsics
// is used uninitialized once they inline here (a false positive, as in
// conv_depthwise_avx512.cpp), so it is off for the file.
#pragma GCC diagnostic ignored "-Wuninitialized"

#include "kernels/x86/avx512_channels.h"
#include "kernels/x86/avx512_kernels.h"
#include "kernels/x86/avx512_math.h"

namespace ampi::avx512 {
namespace {

// Lanes [0, left) set (all of them from 16 up).
__mmask16 tail_mask(int left) {
  return left >= 16 ? static_cast<__mmask16>(0xffff) : static_cast<__mmask16>((1u << left) - 1u);
}

// Two accumulators each, so consecutive adds do not wait on each other; masked-off lanes
// load 0 and add nothing.
float row_sum(const float* in, int c) {
  __m512 a = _mm512_setzero_ps(), b = _mm512_setzero_ps();
  int i = 0;
  for (; i + 32 <= c; i += 32) {
    a = _mm512_add_ps(a, _mm512_loadu_ps(in + i));
    b = _mm512_add_ps(b, _mm512_loadu_ps(in + i + 16));
  }
  for (; i < c; i += 16) a = _mm512_add_ps(a, _mm512_maskz_loadu_ps(tail_mask(c - i), in + i));
  return _mm512_reduce_add_ps(_mm512_add_ps(a, b));
}

float squared_deviations(const float* in, int c, float mean) {
  const __m512 m = _mm512_set1_ps(mean);
  __m512 a = _mm512_setzero_ps(), b = _mm512_setzero_ps();
  int i = 0;
  for (; i + 32 <= c; i += 32) {
    const __m512 d0 = _mm512_sub_ps(_mm512_loadu_ps(in + i), m);
    const __m512 d1 = _mm512_sub_ps(_mm512_loadu_ps(in + i + 16), m);
    a = _mm512_fmadd_ps(d0, d0, a);
    b = _mm512_fmadd_ps(d1, d1, b);
  }
  for (; i < c; i += 16) {
    const __mmask16 mask = tail_mask(c - i);
    const __m512 d = _mm512_maskz_sub_ps(mask, _mm512_maskz_loadu_ps(mask, in + i), m);
    a = _mm512_fmadd_ps(d, d, a);
  }
  return _mm512_reduce_add_ps(_mm512_add_ps(a, b));
}

}  // namespace

void layer_norm_row(const float* in, int c, const float* gamma, const float* beta, float eps, float* out) {
  const float mean = row_sum(in, c) / static_cast<float>(c);
  const __m512 inv_std =
      _mm512_set1_ps(1.0f / std::sqrt(squared_deviations(in, c, mean) / static_cast<float>(c) + eps));
  const __m512 m = _mm512_set1_ps(mean);
  int i = 0;
  for (; i + 16 <= c; i += 16) {
    const __m512 d = _mm512_mul_ps(_mm512_sub_ps(_mm512_loadu_ps(in + i), m), inv_std);
    _mm512_storeu_ps(out + i, _mm512_fmadd_ps(d, _mm512_loadu_ps(gamma + i), _mm512_loadu_ps(beta + i)));
  }
  if (i < c) {
    const __mmask16 mask = tail_mask(c - i);
    const __m512 d = _mm512_mul_ps(_mm512_sub_ps(_mm512_maskz_loadu_ps(mask, in + i), m), inv_std);
    _mm512_mask_storeu_ps(out + i, mask,
                          _mm512_fmadd_ps(d, _mm512_maskz_loadu_ps(mask, gamma + i), _mm512_maskz_loadu_ps(mask, beta + i)));
  }
}

float softmax_block_row(float* scores, int n, float scale, float* running_max, float* running_sum) {
  const __m512 s = _mm512_set1_ps(scale), minus_inf = _mm512_set1_ps(-INFINITY);
  __m512 vmax = minus_inf;
  for (int j = 0; j < n; j += 16) {
    const __mmask16 mask = tail_mask(n - j);
    vmax = _mm512_mask_max_ps(vmax, mask, vmax, _mm512_mul_ps(_mm512_maskz_loadu_ps(mask, scores + j), s));
  }
  const float old_max = *running_max;
  const float new_max = std::max(old_max, _mm512_reduce_max_ps(vmax));
  // As the reference: a block whose every score is -inf contributes nothing, not NaN.
  const __m512 shift = _mm512_set1_ps(new_max == -INFINITY ? 0.0f : new_max);
  __m512 vsum = _mm512_setzero_ps();
  int j = 0;
  for (; j + 16 <= n; j += 16) {
    const __m512 e = exp2_nonpositive(_mm512_sub_ps(_mm512_mul_ps(_mm512_loadu_ps(scores + j), s), shift));
    _mm512_storeu_ps(scores + j, e);
    vsum = _mm512_add_ps(vsum, e);
  }
  if (j < n) {
    const __mmask16 mask = tail_mask(n - j);
    const __m512 e = exp2_nonpositive(_mm512_sub_ps(_mm512_mul_ps(_mm512_maskz_loadu_ps(mask, scores + j), s), shift));
    _mm512_mask_storeu_ps(scores + j, mask, e);
    vsum = _mm512_mask_add_ps(vsum, mask, vsum, e);
  }
  const float factor =
      old_max == -INFINITY ? 0.0f : _mm512_cvtss_f32(exp2_nonpositive(_mm512_set1_ps(old_max - new_max)));
  *running_sum = *running_sum * factor + _mm512_reduce_add_ps(vsum);
  *running_max = new_max;
  return factor;
}

namespace {

// One channel (a depth map resized to the photo): 16 output columns a vector, their 4 taps
// gathered; masked-off lanes gather column 0, which every row has.
void bilinear_row_one_channel(const float* top, const float* bottom, float wy, const int32_t* x0,
                              const int32_t* x1, const float* wx, int out_w, float* out) {
  const __m512 vy = _mm512_set1_ps(wy);
  for (int x = 0; x < out_w; x += 16) {
    const __mmask16 mask = tail_mask(out_w - x);
    const __m512i i0 = _mm512_maskz_loadu_epi32(mask, x0 + x), i1 = _mm512_maskz_loadu_epi32(mask, x1 + x);
    const __m512 vx = _mm512_maskz_loadu_ps(mask, wx + x);
    const __m512 t0 = _mm512_i32gather_ps(i0, top, 4), t1 = _mm512_i32gather_ps(i1, top, 4);
    const __m512 b0 = _mm512_i32gather_ps(i0, bottom, 4), b1 = _mm512_i32gather_ps(i1, bottom, 4);
    const __m512 t = _mm512_fmadd_ps(vx, _mm512_sub_ps(t1, t0), t0);
    const __m512 b = _mm512_fmadd_ps(vx, _mm512_sub_ps(b1, b0), b0);
    _mm512_mask_storeu_ps(out + x, mask, _mm512_fmadd_ps(vy, _mm512_sub_ps(b, t), t));
  }
}

}  // namespace

namespace {
#include "kernels/bilinear_lanes.inl"
}  // namespace

void bilinear_row(const float* top, const float* bottom, float wy, const int32_t* x0, const int32_t* x1,
                  const float* wx, int out_w, int c, float* out) {
  if (c == 1) return bilinear_row_one_channel(top, bottom, wy, x0, x1, wx, out_w, out);
  bilinear_row_channels(top, bottom, wy, x0, x1, wx, out_w, c, out);
}

}  // namespace ampi::avx512
