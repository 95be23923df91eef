// NEON variants of the slicer's row kernels (see row_kernels.h): 8 pixels at a time as
// two 4-float halves; the bilateral filter computes every tap weight as one power of two
// in registers.
#include <cstdint>
#include <cstring>

#include "slicing/row_kernels.h"

#if defined(__aarch64__)
#include <arm_neon.h>

namespace ampi::slicing::neon {
namespace {

// 2^y for y <= 0, as in the x86 variants.
inline float32x4_t exp2_nonpositive(float32x4_t y) {
  y = vmaxq_f32(y, vdupq_n_f32(-126.0f));
  const float32x4_t n = vrndnq_f32(y);
  const float32x4_t f = vsubq_f32(y, n);
  float32x4_t p = vdupq_n_f32(1.540353039e-4f);
  p = vfmaq_f32(vdupq_n_f32(1.333355815e-3f), p, f);
  p = vfmaq_f32(vdupq_n_f32(9.618129108e-3f), p, f);
  p = vfmaq_f32(vdupq_n_f32(5.550410866e-2f), p, f);
  p = vfmaq_f32(vdupq_n_f32(2.402265070e-1f), p, f);
  p = vfmaq_f32(vdupq_n_f32(6.931471806e-1f), p, f);
  p = vfmaq_f32(vdupq_n_f32(1.0f), p, f);
  const int32x4_t e = vshlq_n_s32(vaddq_s32(vcvtq_s32_f32(n), vdupq_n_s32(127)), 23);
  return vmulq_f32(p, vreinterpretq_f32_s32(e));
}

struct Floats8 {
  float32x4_t lo, hi;
};

inline Floats8 load8(const uint8_t* p) {
  uint8x8_t bytes;
  std::memcpy(&bytes, p, 8);
  const uint16x8_t wide = vmovl_u8(bytes);
  return {vcvtq_f32_u32(vmovl_u16(vget_low_u16(wide))), vcvtq_f32_u32(vmovl_u16(vget_high_u16(wide)))};
}

struct Sums {
  float32x4_t sum = vdupq_n_f32(0), wsum = vdupq_n_f32(0);
};

inline void add_tap(float32x4_t v, float32x4_t v0, float32x4_t coeff, float32x4_t log2_space, Sums& s) {
  const float32x4_t d = vsubq_f32(v, v0);
  const float32x4_t w = exp2_nonpositive(vfmaq_f32(log2_space, vmulq_f32(d, d), coeff));
  s.sum = vfmaq_f32(s.sum, w, v);
  s.wsum = vaddq_f32(s.wsum, w);
}

inline void filter8(const uint8_t* c, const BilateralTaps& taps, uint8_t* out) {
  const Floats8 v0 = load8(c);
  const float32x4_t coeff = vdupq_n_f32(taps.color_log2_coeff);
  Sums lo, hi;
  for (int k = 0; k < taps.count; ++k) {
    const Floats8 v = load8(c + taps.offset[k]);
    const float32x4_t log2_space = vdupq_n_f32(taps.log2_space_weight[k]);
    add_tap(v.lo, v0.lo, coeff, log2_space, lo);
    add_tap(v.hi, v0.hi, coeff, log2_space, hi);
  }
  // Round to nearest even, then 8 values in [0, 255] down to bytes.
  const uint32x4_t q_lo = vcvtnq_u32_f32(vdivq_f32(lo.sum, lo.wsum));
  const uint32x4_t q_hi = vcvtnq_u32_f32(vdivq_f32(hi.sum, hi.wsum));
  const uint8x8_t bytes = vqmovn_u16(vcombine_u16(vqmovn_u32(q_lo), vqmovn_u32(q_hi)));
  std::memcpy(out, &bytes, 8);
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

void bilateral_row(const uint8_t* center, int width, const BilateralTaps& taps, uint8_t* out) {
  if (width < 8) return scalar::bilateral_row(center, width, taps, out);
  int x = 0;
  for (; x + 8 <= width; x += 8) filter8(center + x, taps, out + x);
  // The last partial block: the final 8 pixels again, overlapping (same values).
  if (x < width) filter8(center + width - 8, taps, out + width - 8);
}

}  // namespace ampi::slicing::neon
#endif  // __aarch64__
