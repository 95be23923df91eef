// NEON variants of the slicer's row kernels (see row_kernels.h): 8 pixels at a time as
// two 4-float halves; the bilateral weights are computed in registers as powers of two
// (exp2_nonpositive).
#include <cstdint>
#include <cstring>

#include "kernels/arm/neon_math.h"
#include "slicing/row_kernels.h"

namespace ampi::slicing::neon {
namespace {

struct Floats8 {
  float32x4_t lo, hi;
};

// The first `count` (1..8) bytes at p as floats; lanes past count hold 0. A short block
// goes through a copy so that nothing past the row is read.
inline Floats8 load_levels(const uint8_t* p, int count) {
  uint8_t copy[8] = {};
  if (count < 8) std::memcpy(copy, p, count);
  const uint16x8_t wide = vmovl_u8(vld1_u8(count < 8 ? copy : p));
  return {vcvtq_f32_u32(vmovl_u16(vget_low_u16(wide))), vcvtq_f32_u32(vmovl_u16(vget_high_u16(wide)))};
}

inline Floats8 load_floats(const float* p, int count) {
  if (count == 8) return {vld1q_f32(p), vld1q_f32(p + 4)};
  float copy[8] = {};
  std::memcpy(copy, p, count * sizeof(float));
  return {vld1q_f32(copy), vld1q_f32(copy + 4)};
}

inline void store_floats(float* p, Floats8 v, int count) {
  if (count == 8) {
    vst1q_f32(p, v.lo);
    vst1q_f32(p + 4, v.hi);
    return;
  }
  float copy[8];
  vst1q_f32(copy, v.lo);
  vst1q_f32(copy + 4, v.hi);
  std::memcpy(p, copy, count * sizeof(float));
}

// min((x - lo) * scale, 255) on 4 values in double, back to float.
inline float32x4_t normalize4(float32x4_t x, float64x2_t lo, float64x2_t scale) {
  const float64x2_t top = vdupq_n_f64(255.0);
  const float64x2_t a = vminq_f64(vmulq_f64(vsubq_f64(vcvt_f64_f32(vget_low_f32(x)), lo), scale), top);
  const float64x2_t b = vminq_f64(vmulq_f64(vsubq_f64(vcvt_high_f64_f32(x), lo), scale), top);
  return vcvt_high_f32_f64(vcvt_f32_f64(a), b);
}

}  // namespace

void range_row(const float* in, int n, ValueRange& range) {
  int x = 0;
  if (n >= 4) {
    float32x4_t lo = vdupq_n_f32(range.lo), hi = vdupq_n_f32(range.hi);
    uint32x4_t finite = vdupq_n_u32(~0u);
    for (; x + 4 <= n; x += 4) {
      const float32x4_t v = vld1q_f32(in + x);
      // v - v is 0 for a finite v, NaN for an infinite or NaN one.
      finite = vandq_u32(finite, vceqq_f32(vsubq_f32(v, v), vdupq_n_f32(0.0f)));
      lo = vminq_f32(lo, v);
      hi = vmaxq_f32(hi, v);
    }
    range.lo = vminvq_f32(lo);
    range.hi = vmaxvq_f32(hi);
    range.finite = range.finite && vminvq_u32(finite) == ~0u;
  }
  scalar::range_row(in + x, n - x, range);
}

void normalize_row(const float* in, int n, double lo, double scale, float* value, uint8_t* level) {
  const float64x2_t lo2 = vdupq_n_f64(lo), scale2 = vdupq_n_f64(scale);
  int x = 0;
  for (; x + 8 <= n; x += 8) {
    const float32x4_t a = normalize4(vld1q_f32(in + x), lo2, scale2);
    const float32x4_t b = normalize4(vld1q_f32(in + x + 4), lo2, scale2);
    vst1q_f32(value + x, a);
    vst1q_f32(value + x + 4, b);
    const uint16x8_t wide = vcombine_u16(vqmovn_u32(vcvtnq_u32_f32(a)), vqmovn_u32(vcvtnq_u32_f32(b)));
    vst1_u8(level + x, vqmovn_u16(wide));  // nearest, ties to even
  }
  scalar::normalize_row(in + x, n - x, lo, scale, value + x, level + x);
}

void bilateral_weights(const uint8_t* p, int n, const BilateralPairs& pairs, float* const* weight) {
  const float32x4_t coeff = vdupq_n_f32(pairs.color_log2_coeff);
  auto weigh = [&](float32x4_t v, float32x4_t v0, float32x4_t log2_space) {
    const float32x4_t d = vsubq_f32(v, v0);
    return ampi::neon::exp2_nonpositive(vfmaq_f32(log2_space, vmulq_f32(d, d), coeff));
  };
  for (int x = 0; x < n; x += 8) {
    const int count = n - x < 8 ? n - x : 8;
    const Floats8 v0 = load_levels(p + x, count);
    for (int h = 0; h < pairs.count; ++h) {
      const Floats8 v = load_levels(p + x + pairs.offset[h], count);
      const float32x4_t log2_space = vdupq_n_f32(pairs.log2_space_weight[h]);
      store_floats(weight[h] + x, {weigh(v.lo, v0.lo, log2_space), weigh(v.hi, v0.hi, log2_space)}, count);
    }
  }
}

void bilateral_combine(const uint8_t* center, int n, const BilateralTaps& taps, uint8_t* out) {
  for (int x = 0; x < n; x += 8) {
    const int count = n - x < 8 ? n - x : 8;
    float32x4_t sum_lo = vdupq_n_f32(0), sum_hi = sum_lo, wsum_lo = sum_lo, wsum_hi = sum_lo;
    for (int k = 0; k < taps.count; ++k) {
      const Floats8 w = load_floats(taps.weight[k] + x, count);
      const Floats8 v = load_levels(center + x + taps.offset[k], count);
      sum_lo = vfmaq_f32(sum_lo, w.lo, v.lo);
      sum_hi = vfmaq_f32(sum_hi, w.hi, v.hi);
      wsum_lo = vaddq_f32(wsum_lo, w.lo);
      wsum_hi = vaddq_f32(wsum_hi, w.hi);
    }
    // Round to nearest even; lanes past count are 0 / 0, not stored.
    const uint32x4_t q_lo = vcvtnq_u32_f32(vdivq_f32(sum_lo, wsum_lo));
    const uint32x4_t q_hi = vcvtnq_u32_f32(vdivq_f32(sum_hi, wsum_hi));
    uint8_t bytes[8];
    vst1_u8(bytes, vqmovn_u16(vcombine_u16(vqmovn_u32(q_lo), vqmovn_u32(q_hi))));
    std::memcpy(out + x, bytes, count);
  }
}

void snap_row(const SnapRowInputs& in, int n, float min_step, float margin, float* out, uint8_t* band) {
  const float32x4_t step = vdupq_n_f32(min_step), m = vdupq_n_f32(margin), neg_m = vdupq_n_f32(-margin);
  int x = 0;
  for (; x + 4 <= n; x += 4) {
    const float32x4_t lo = vld1q_f32(in.lo + x), hi = vld1q_f32(in.hi + x), d = vld1q_f32(in.disparity + x);
    const float32x4_t spread = vsubq_f32(hi, lo);
    const uint32x4_t edge = vcgeq_f32(spread, step);
    // vfmaq_f32(c, a, b) = c + a * b, fused.
    const uint32x4_t inside = vandq_u32(vcgtq_f32(d, vfmaq_f32(lo, m, spread)), vcltq_f32(d, vfmaq_f32(hi, neg_m, spread)));
    float32x4_t fit = vfmaq_f32(vaddq_f32(vld1q_f32(in.b + x), d), vld1q_f32(in.a0 + x), vld1q_f32(in.blue + x));
    fit = vfmaq_f32(fit, vld1q_f32(in.a1 + x), vld1q_f32(in.green + x));
    fit = vfmaq_f32(fit, vld1q_f32(in.a2 + x), vld1q_f32(in.red + x));
    const uint32x4_t near = vcgeq_f32(fit, vmulq_f32(vaddq_f32(lo, hi), vdupq_n_f32(0.5f)));
    const float32x4_t side = vbslq_f32(near, hi, lo);
    vst1q_f32(out + x, vbslq_f32(vandq_u32(edge, inside), side, d));
    const uint16x4_t narrow = vmovn_u32(vandq_u32(edge, vdupq_n_u32(255)));
    uint8_t bytes[8];
    vst1_u8(bytes, vmovn_u16(vcombine_u16(narrow, narrow)));
    std::memcpy(band + x, bytes, 4);
  }
  scalar::snap_row({in.disparity + x, in.blue + x, in.green + x, in.red + x, in.a0 + x, in.a1 + x, in.a2 + x,
                    in.b + x, in.lo + x, in.hi + x},
                   n - x, min_step, margin, out + x, band + x);
}

}  // namespace ampi::slicing::neon
