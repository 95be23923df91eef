// NEON transformer row kernels (contracts in kernels/kernel_list.def), 4 floats a vector.
// NEON has no masked loads: a tail of fewer than 4 floats goes through a 4-float buffer,
// so it takes the vector path too (the vector exp included).
#include <cmath>

#include "kernels/arm/neon_channels.h"
#include "kernels/arm/neon_kernels.h"
#include "kernels/arm/neon_math.h"

namespace ampi::neon {
namespace {

// The first `left` floats of p (left < 4), the other lanes `fill`.
float32x4_t load_tail(const float* p, int left, float fill) {
  float lanes[4] = {fill, fill, fill, fill};
  for (int i = 0; i < left; ++i) lanes[i] = p[i];
  return vld1q_f32(lanes);
}

void store_tail(float* p, int left, float32x4_t v) {
  float lanes[4];
  vst1q_f32(lanes, v);
  for (int i = 0; i < left; ++i) p[i] = lanes[i];
}

// Two accumulators each, so consecutive adds do not wait on each other.
float row_sum(const float* in, int c) {
  float32x4_t a = vdupq_n_f32(0.0f), b = vdupq_n_f32(0.0f);
  int i = 0;
  for (; i + 8 <= c; i += 8) {
    a = vaddq_f32(a, vld1q_f32(in + i));
    b = vaddq_f32(b, vld1q_f32(in + i + 4));
  }
  for (; i + 4 <= c; i += 4) a = vaddq_f32(a, vld1q_f32(in + i));
  if (i < c) a = vaddq_f32(a, load_tail(in + i, c - i, 0.0f));
  return vaddvq_f32(vaddq_f32(a, b));
}

float squared_deviations(const float* in, int c, float mean) {
  const float32x4_t m = vdupq_n_f32(mean);
  float32x4_t a = vdupq_n_f32(0.0f), b = vdupq_n_f32(0.0f);
  int i = 0;
  for (; i + 8 <= c; i += 8) {
    const float32x4_t d0 = vsubq_f32(vld1q_f32(in + i), m), d1 = vsubq_f32(vld1q_f32(in + i + 4), m);
    a = vfmaq_f32(a, d0, d0);
    b = vfmaq_f32(b, d1, d1);
  }
  for (; i + 4 <= c; i += 4) {
    const float32x4_t d = vsubq_f32(vld1q_f32(in + i), m);
    a = vfmaq_f32(a, d, d);
  }
  if (i < c) {
    // Lanes past the row hold the mean: they deviate by 0.
    const float32x4_t d = vsubq_f32(load_tail(in + i, c - i, mean), m);
    a = vfmaq_f32(a, d, d);
  }
  return vaddvq_f32(vaddq_f32(a, b));
}

float32x4_t normalized(float32x4_t x, float32x4_t mean, float32x4_t inv_std, float32x4_t gamma, float32x4_t beta) {
  return vfmaq_f32(beta, vmulq_f32(vsubq_f32(x, mean), inv_std), gamma);
}

}  // namespace

void layer_norm_row(const float* in, int c, const float* gamma, const float* beta, float eps, float* out) {
  const float mean = row_sum(in, c) / static_cast<float>(c);
  const float32x4_t inv_std =
      vdupq_n_f32(1.0f / std::sqrt(squared_deviations(in, c, mean) / static_cast<float>(c) + eps));
  const float32x4_t m = vdupq_n_f32(mean);
  int i = 0;
  for (; i + 4 <= c; i += 4)
    vst1q_f32(out + i, normalized(vld1q_f32(in + i), m, inv_std, vld1q_f32(gamma + i), vld1q_f32(beta + i)));
  if (i < c) {
    const int left = c - i;
    store_tail(out + i, left,
               normalized(load_tail(in + i, left, 0.0f), m, inv_std, load_tail(gamma + i, left, 0.0f),
                          load_tail(beta + i, left, 0.0f)));
  }
}

float softmax_block_row(float* scores, int n, float scale, float* running_max, float* running_sum) {
  const float32x4_t s = vdupq_n_f32(scale);
  float32x4_t vmax = vdupq_n_f32(-INFINITY);
  int j = 0;
  for (; j + 4 <= n; j += 4) vmax = vmaxq_f32(vmax, vmulq_f32(vld1q_f32(scores + j), s));
  float block_max = vmaxvq_f32(vmax);
  for (; j < n; ++j) block_max = std::max(block_max, scores[j] * scale);
  const float old_max = *running_max;
  const float new_max = std::max(old_max, block_max);
  // As the reference: a block whose every score is -inf contributes nothing, not NaN.
  const float32x4_t shift = vdupq_n_f32(new_max == -INFINITY ? 0.0f : new_max);
  float32x4_t vsum = vdupq_n_f32(0.0f);
  j = 0;
  for (; j + 4 <= n; j += 4) {
    const float32x4_t e = exp2_nonpositive(vsubq_f32(vmulq_f32(vld1q_f32(scores + j), s), shift));
    vst1q_f32(scores + j, e);
    vsum = vaddq_f32(vsum, e);
  }
  if (j < n) {
    const int left = n - j;
    // Lanes past the block hold the exp of a 0 score: dropped from the sum.
    const float32x4_t e = exp2_nonpositive(vsubq_f32(vmulq_f32(load_tail(scores + j, left, 0.0f), s), shift));
    store_tail(scores + j, left, e);
    static const int32_t kLane[4] = {0, 1, 2, 3};
    const uint32x4_t live = vcltq_s32(vld1q_s32(kLane), vdupq_n_s32(left));
    vsum = vaddq_f32(vsum, vreinterpretq_f32_u32(vandq_u32(live, vreinterpretq_u32_f32(e))));
  }
  const float factor = old_max == -INFINITY ? 0.0f : vgetq_lane_f32(exp2_nonpositive(vdupq_n_f32(old_max - new_max)), 0);
  *running_sum = *running_sum * factor + vaddvq_f32(vsum);
  *running_max = new_max;
  return factor;
}

namespace {
#include "kernels/bilinear_lanes.inl"
}  // namespace

void bilinear_row(const float* top, const float* bottom, float wy, const int32_t* x0, const int32_t* x1,
                  const float* wx, int out_w, int c, float* out) {
  bilinear_row_channels(top, bottom, wy, x0, x1, wx, out_w, c, out);
}

}  // namespace ampi::neon
