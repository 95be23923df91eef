// AVX2 transformer row kernels (contracts in kernels/kernel_list.def). The row kernels'
// tails go through masked loads and stores, so every element takes the vector path and
// no scalar helper from a shared header is compiled with AVX2 flags (cmake/isa.cmake);
// whole vectors use plain ones, as vmaskmovps stores are slow on AMD's cores (measured:
// softmax 3x slower with every store masked). bilinear_row over several channels is the
// lane-generic kernels/bilinear_lanes.inl, leftover channels scalar as in avx2_channels.h.
#include <cmath>

#include "kernels/x86/avx2_channels.h"
#include "kernels/x86/avx2_kernels.h"
#include "kernels/x86/avx2_math.h"

namespace ampi::avx2 {
namespace {

// Lanes [0, left) set (all of them from 8 up).
__m256i tail_mask(int left) {
  return _mm256_cmpgt_epi32(_mm256_set1_epi32(left), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
}

float horizontal_max(__m256 v) {
  __m128 m = _mm_max_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  m = _mm_max_ps(m, _mm_movehl_ps(m, m));
  m = _mm_max_ss(m, _mm_movehdup_ps(m));
  return _mm_cvtss_f32(m);
}

// sum of in[i] and sum of (in[i] - mean)^2, two accumulators each so consecutive adds
// do not wait on each other.
float row_sum(const float* in, int c) {
  __m256 a = _mm256_setzero_ps(), b = _mm256_setzero_ps();
  int i = 0;
  for (; i + 16 <= c; i += 16) {
    a = _mm256_add_ps(a, _mm256_loadu_ps(in + i));
    b = _mm256_add_ps(b, _mm256_loadu_ps(in + i + 8));
  }
  for (; i < c; i += 8) a = _mm256_add_ps(a, _mm256_maskload_ps(in + i, tail_mask(c - i)));
  return horizontal_sum(_mm256_add_ps(a, b));
}

float squared_deviations(const float* in, int c, float mean) {
  const __m256 m = _mm256_set1_ps(mean);
  __m256 a = _mm256_setzero_ps(), b = _mm256_setzero_ps();
  int i = 0;
  for (; i + 16 <= c; i += 16) {
    const __m256 d0 = _mm256_sub_ps(_mm256_loadu_ps(in + i), m);
    const __m256 d1 = _mm256_sub_ps(_mm256_loadu_ps(in + i + 8), m);
    a = _mm256_fmadd_ps(d0, d0, a);
    b = _mm256_fmadd_ps(d1, d1, b);
  }
  for (; i < c; i += 8) {
    const __m256i mask = tail_mask(c - i);
    // Masked-off lanes load 0; their deviation is zeroed before it is squared.
    const __m256 d = _mm256_and_ps(_mm256_sub_ps(_mm256_maskload_ps(in + i, mask), m), _mm256_castsi256_ps(mask));
    a = _mm256_fmadd_ps(d, d, a);
  }
  return horizontal_sum(_mm256_add_ps(a, b));
}

}  // namespace

void layer_norm_row(const float* in, int c, const float* gamma, const float* beta, float eps, float* out) {
  const float mean = row_sum(in, c) / static_cast<float>(c);
  const __m256 inv_std = _mm256_set1_ps(1.0f / std::sqrt(squared_deviations(in, c, mean) / static_cast<float>(c) + eps));
  const __m256 m = _mm256_set1_ps(mean);
  int i = 0;
  for (; i + 8 <= c; i += 8) {
    const __m256 d = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(in + i), m), inv_std);
    _mm256_storeu_ps(out + i, _mm256_fmadd_ps(d, _mm256_loadu_ps(gamma + i), _mm256_loadu_ps(beta + i)));
  }
  if (i < c) {
    const __m256i mask = tail_mask(c - i);
    const __m256 d = _mm256_mul_ps(_mm256_sub_ps(_mm256_maskload_ps(in + i, mask), m), inv_std);
    _mm256_maskstore_ps(out + i, mask,
                        _mm256_fmadd_ps(d, _mm256_maskload_ps(gamma + i, mask), _mm256_maskload_ps(beta + i, mask)));
  }
}

float softmax_block_row(float* scores, int n, float scale, float* running_max, float* running_sum) {
  const __m256 s = _mm256_set1_ps(scale), minus_inf = _mm256_set1_ps(-INFINITY);
  __m256 vmax = minus_inf;
  for (int j = 0; j < n; j += 8) {
    const __m256i mask = tail_mask(n - j);
    const __m256 v = _mm256_mul_ps(_mm256_maskload_ps(scores + j, mask), s);
    vmax = _mm256_max_ps(vmax, _mm256_blendv_ps(minus_inf, v, _mm256_castsi256_ps(mask)));
  }
  const float old_max = *running_max;
  const float new_max = std::max(old_max, horizontal_max(vmax));
  // As the reference: a block whose every score is -inf contributes nothing, not NaN.
  const __m256 shift = _mm256_set1_ps(new_max == -INFINITY ? 0.0f : new_max);
  __m256 vsum = _mm256_setzero_ps();
  int j = 0;
  for (; j + 8 <= n; j += 8) {
    const __m256 e = exp2_nonpositive(_mm256_sub_ps(_mm256_mul_ps(_mm256_loadu_ps(scores + j), s), shift));
    _mm256_storeu_ps(scores + j, e);
    vsum = _mm256_add_ps(vsum, e);
  }
  if (j < n) {
    const __m256i mask = tail_mask(n - j);
    const __m256 e = exp2_nonpositive(_mm256_sub_ps(_mm256_mul_ps(_mm256_maskload_ps(scores + j, mask), s), shift));
    _mm256_maskstore_ps(scores + j, mask, e);
    vsum = _mm256_add_ps(vsum, _mm256_and_ps(e, _mm256_castsi256_ps(mask)));
  }
  const float factor =
      old_max == -INFINITY ? 0.0f : _mm256_cvtss_f32(exp2_nonpositive(_mm256_set1_ps(old_max - new_max)));
  *running_sum = *running_sum * factor + horizontal_sum(vsum);
  *running_max = new_max;
  return factor;
}

namespace {

// One channel (a depth map resized to the photo): 8 output columns a vector, their 4 taps
// gathered; masked-off lanes gather column 0, which every row has.
__m256 bilinear_columns(const float* top, const float* bottom, __m256 vy, __m256i i0, __m256i i1, __m256 vx) {
  const __m256 t0 = _mm256_i32gather_ps(top, i0, 4), t1 = _mm256_i32gather_ps(top, i1, 4);
  const __m256 b0 = _mm256_i32gather_ps(bottom, i0, 4), b1 = _mm256_i32gather_ps(bottom, i1, 4);
  const __m256 t = _mm256_fmadd_ps(vx, _mm256_sub_ps(t1, t0), t0);
  const __m256 b = _mm256_fmadd_ps(vx, _mm256_sub_ps(b1, b0), b0);
  return _mm256_fmadd_ps(vy, _mm256_sub_ps(b, t), t);
}

void bilinear_row_one_channel(const float* top, const float* bottom, float wy, const int32_t* x0,
                              const int32_t* x1, const float* wx, int out_w, float* out) {
  const __m256 vy = _mm256_set1_ps(wy);
  int x = 0;
  for (; x + 8 <= out_w; x += 8) {
    const __m256i i0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(x0 + x));
    const __m256i i1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(x1 + x));
    _mm256_storeu_ps(out + x, bilinear_columns(top, bottom, vy, i0, i1, _mm256_loadu_ps(wx + x)));
  }
  if (x < out_w) {
    const __m256i mask = tail_mask(out_w - x);
    const __m256i i0 = _mm256_maskload_epi32(x0 + x, mask), i1 = _mm256_maskload_epi32(x1 + x, mask);
    _mm256_maskstore_ps(out + x, mask, bilinear_columns(top, bottom, vy, i0, i1, _mm256_maskload_ps(wx + x, mask)));
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

}  // namespace ampi::avx2
