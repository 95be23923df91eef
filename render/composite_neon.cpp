// NEON variant of the compositor kernels (AArch64): coordinates for 4 pixels at once,
// then one footprint per pixel, each pixel's BGRA in one float32x4 register; a 128-bit
// load brings a pixel and its right neighbour as 8 halves.
//
// Cycle budget (bench/arm_model.py, llvm-mca's Neoverse-N1 model for Cortex-A76): FCVTL,
// FRINTM, FCVTZS, MLA and FDIV issue on one of the two vector pipes (V0) only, and
// the 16 FCVTLs of four footprints alone took 32 of its cycles. The halves are widened
// on the integer side instead (widen_scaled), which V1 takes.
#include <arm_neon.h>

#include <cstdint>
#include <cstring>

#include "render/composite_kernels.h"

namespace ampi::render::neon {
namespace {

struct Footprints {
  int32_t top_left[4];  // pixel index of each footprint's top-left pixel
  float ax[4], ay[4];   // bilinear weights of the right and bottom neighbours
};

struct RowMap {
  float32x4_t m0, m3, m6;
  float32x4_t row_x, row_y, row_w;  // the terms constant along the row
  float32x4_t max_u, max_v;
  int32x4_t stride;
  int32x4_t stored_x, stored_y, stored_width, stored_height;
};

RowMap row_map(const PlaneView& plane, const InverseHomography& h, int y) {
  const float* m = h.m;
  const float fy = static_cast<float>(y);
  RowMap r;
  r.m0 = vdupq_n_f32(m[0]);
  r.m3 = vdupq_n_f32(m[3]);
  r.m6 = vdupq_n_f32(m[6]);
  r.row_x = vdupq_n_f32(m[1] * fy + m[2]);
  r.row_y = vdupq_n_f32(m[4] * fy + m[5]);
  r.row_w = vdupq_n_f32(m[7] * fy + m[8]);
  r.max_u = vdupq_n_f32(static_cast<float>(plane.width));
  r.max_v = vdupq_n_f32(static_cast<float>(plane.height));
  r.stride = vdupq_n_s32(static_cast<int32_t>(plane.stride));
  r.stored_x = vdupq_n_s32(plane.stored_x);
  r.stored_y = vdupq_n_s32(plane.stored_y);
  r.stored_width = vdupq_n_s32(plane.stored_width);
  r.stored_height = vdupq_n_s32(plane.stored_height);
  return r;
}

// The footprints of output columns xs (whole numbers, exact in float below 2^24).
Footprints locate(const RowMap& r, float32x4_t xs) {
  const float32x4_t px = vfmaq_f32(r.row_x, r.m0, xs);
  const float32x4_t py = vfmaq_f32(r.row_y, r.m3, xs);
  const float32x4_t pw = vfmaq_f32(r.row_w, r.m6, xs);
  const float32x4_t border = vdupq_n_f32(-1.0f);
  const uint32x4_t in_front = vcgtq_f32(pw, vdupq_n_f32(kMinHomogeneousW));
  const float32x4_t inv_w = vdivq_f32(vdupq_n_f32(1.0f), pw);
  float32x4_t u = vbslq_f32(in_front, vmulq_f32(px, inv_w), border);
  float32x4_t v = vbslq_f32(in_front, vmulq_f32(py, inv_w), border);
  // maxnm returns the number when the other operand is NaN: NaN goes to the border.
  u = vminq_f32(vmaxnmq_f32(u, border), r.max_u);
  v = vminq_f32(vmaxnmq_f32(v, border), r.max_v);
  const float32x4_t fu = vrndmq_f32(u), fv = vrndmq_f32(v);
  Footprints f;
  vst1q_f32(f.ax, vsubq_f32(u, fu));
  vst1q_f32(f.ay, vsubq_f32(v, fv));
  // The stored block's column and row, clamped to [-2, stored size] (composite_kernels.h).
  const int32x4_t before = vdupq_n_s32(-2);
  const int32x4_t column =
      vminq_s32(vmaxq_s32(vsubq_s32(vcvtq_s32_f32(fu), r.stored_x), before), r.stored_width);
  const int32x4_t row = vminq_s32(vmaxq_s32(vsubq_s32(vcvtq_s32_f32(fv), r.stored_y), before), r.stored_height);
  vst1q_s32(f.top_left, vmlaq_s32(column, row, r.stride));
  return f;
}

// Four halves widened to floats scaled by 2^-112, by shifting bits instead of FCVTL:
// a half's exponent and mantissa (its low 15 bits; the sign is masked, a layer holds no
// negative value but may hold -0) moved up 13 bits are the float with the half's
// exponent field, which reads 2^(15 - 127) times the half's value. Exact for every
// finite half, subnormals included.
inline float32x4_t widen_scaled(uint16x4_t halves) {
  return vreinterpretq_f32_u32(vshll_n_u16(halves, 13));
}
inline float32x4_t widen_scaled_high(uint16x8_t halves) {
  return vreinterpretq_f32_u32(vshll_high_n_u16(halves, 13));
}
constexpr float kUnscale = 0x1p112f;

// The bilinear sample, computed on the scaled values and scaled back once. Scaling by a
// power of two commutes with rounding while the values stay normal floats (a half down
// to 2^-14), so the sample rounds as the reference's except below that, where the
// difference is under 2^-37.
float32x4_t sample(const PlaneView& plane, int32_t index, float ax_value, float ay_value) {
  const uint16_t* p = plane.origin + 4 * static_cast<int64_t>(index);
  const uint16x8_t magnitude = vdupq_n_u16(0x7fff);
  const uint16x8_t top = vandq_u16(vld1q_u16(p), magnitude);
  const uint16x8_t bottom = vandq_u16(vld1q_u16(p + 4 * plane.stride), magnitude);
  const float32x4_t tl = widen_scaled(vget_low_u16(top)), tr = widen_scaled_high(top);
  const float32x4_t bl = widen_scaled(vget_low_u16(bottom)), br = widen_scaled_high(bottom);
  const float32x4_t ax = vdupq_n_f32(ax_value), ay = vdupq_n_f32(ay_value);
  const float32x4_t t = vfmaq_f32(tl, ax, vsubq_f32(tr, tl));
  const float32x4_t b = vfmaq_f32(bl, ax, vsubq_f32(br, bl));
  return vmulq_n_f32(vfmaq_f32(t, ay, vsubq_f32(b, t)), kUnscale);
}

// accum = sample + accum * (1 - sample.alpha)
void over(float* accum, float32x4_t s) {
  const float32x4_t keep = vsubq_f32(vdupq_n_f32(1.0f), vdupq_laneq_f32(s, 3));
  vst1q_f32(accum, vfmaq_f32(s, vld1q_f32(accum), keep));
}

uint8x8_t round_to_bytes(float32x4_t lo, float32x4_t hi) {
  const int16x8_t words = vcombine_s16(vqmovn_s32(vcvtnq_s32_f32(vmulq_n_f32(lo, 255.0f))),
                                       vqmovn_s32(vcvtnq_s32_f32(vmulq_n_f32(hi, 255.0f))));
  return vqmovun_s16(words);
}

}  // namespace

void warp_over_row(const PlaneView& plane, const InverseHomography& h, int y, int x_begin,
                   int count, float* accum) {
  const RowMap r = row_map(plane, h, y);
  const float lane_offsets[4] = {0, 1, 2, 3};
  float32x4_t xs = vaddq_f32(vdupq_n_f32(static_cast<float>(x_begin)), vld1q_f32(lane_offsets));
  // The next four footprints are located before these four are sampled: one group's
  // chain (divide, floor, index, load, blend) is longer than an out-of-order core's
  // window, and this way two groups' chains overlap.
  Footprints f = locate(r, xs);
  int i = 0;
  for (; i + 4 <= count; i += 4) {
    xs = vaddq_f32(xs, vdupq_n_f32(4.0f));
    const Footprints next = locate(r, xs);
    for (int k = 0; k < 4; ++k) over(accum + 4 * (i + k), sample(plane, f.top_left[k], f.ax[k], f.ay[k]));
    f = next;
  }
  for (int k = 0; i + k < count; ++k)
    over(accum + 4 * (i + k), sample(plane, f.top_left[k], f.ax[k], f.ay[k]));
}

void shift_over_row(const PlaneView& plane, float du, float dv, int y, int x_begin, int count,
                    float* accum) {
  const ShiftSpan span = shift_span(plane, du, dv, y, x_begin, count);
  if (span.empty) return;
  const int32_t row_start = static_cast<int32_t>(span.row * plane.stride + span.column_offset);
  for (int x = span.first; x <= span.last; ++x)
    over(accum + 4 * (x - x_begin), sample(plane, row_start + x, span.ax, span.ay));
}

void accum_to_bgr(const float* accum, int count, uint8_t* bgr) {
  int i = 0;
  for (; i + 8 <= count; i += 8) {
    // vld4 splits four pixels into B, G, R and A vectors; vst3 interleaves B, G, R again.
    const float32x4x4_t lo = vld4q_f32(accum + 4 * i);
    const float32x4x4_t hi = vld4q_f32(accum + 4 * i + 16);
    uint8x8x3_t out;
    for (int k = 0; k < 3; ++k) out.val[k] = round_to_bytes(lo.val[k], hi.val[k]);
    vst3_u8(bgr + 3 * i, out);
  }
  for (; i < count; ++i) {
    const float32x4_t p = vld1q_f32(accum + 4 * i);
    uint8_t bytes[8];
    vst1_u8(bytes, round_to_bytes(p, p));
    std::memcpy(bgr + 3 * i, bytes, 3);
  }
}

}  // namespace ampi::render::neon
