// AVX2 + FMA + F16C variant of the compositor kernels. Coordinates are computed for 8
// pixels at once; the samples are then read two pixels per 256-bit register: one 128-bit
// load brings a pixel and its right neighbour (the layer is BGRA halves, 8 bytes a pixel),
// so a bilinear footprint costs two loads and no gathers.
#include <immintrin.h>

#include <cstdint>
#include <cstring>

#include "render/composite_kernels.h"

namespace ampi::render::avx2 {
namespace {

// Where 8 consecutive output pixels sample the layer.
struct Footprints {
  alignas(32) int32_t top_left[8];  // pixel index of each footprint's top-left pixel
  __m256 ax, ay;                    // bilinear weights of the right and bottom neighbours
};

struct RowMap {
  __m256 m0, m3, m6;          // the x coefficients of the homography rows
  __m256 row_x, row_y, row_w;  // the terms constant along the row
  __m256 max_u, max_v;
  __m256i stride;
  __m256i stored_x, stored_y, stored_width, stored_height;
};

RowMap row_map(const PlaneView& plane, const InverseHomography& h, int y) {
  const float* m = h.m;
  const float fy = static_cast<float>(y);
  RowMap r;
  r.m0 = _mm256_set1_ps(m[0]);
  r.m3 = _mm256_set1_ps(m[3]);
  r.m6 = _mm256_set1_ps(m[6]);
  // Same expressions as the scalar reference, so the row terms are bit-identical.
  r.row_x = _mm256_set1_ps(m[1] * fy + m[2]);
  r.row_y = _mm256_set1_ps(m[4] * fy + m[5]);
  r.row_w = _mm256_set1_ps(m[7] * fy + m[8]);
  r.max_u = _mm256_set1_ps(static_cast<float>(plane.width));
  r.max_v = _mm256_set1_ps(static_cast<float>(plane.height));
  r.stride = _mm256_set1_epi32(static_cast<int32_t>(plane.stride));
  r.stored_x = _mm256_set1_epi32(plane.stored_x);
  r.stored_y = _mm256_set1_epi32(plane.stored_y);
  r.stored_width = _mm256_set1_epi32(plane.stored_width);
  r.stored_height = _mm256_set1_epi32(plane.stored_height);
  return r;
}

Footprints locate(const RowMap& r, int x) {
  const __m256 xs = _mm256_add_ps(_mm256_set1_ps(static_cast<float>(x)),
                                  _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7));
  const __m256 px = _mm256_fmadd_ps(r.m0, xs, r.row_x);
  const __m256 py = _mm256_fmadd_ps(r.m3, xs, r.row_y);
  const __m256 pw = _mm256_fmadd_ps(r.m6, xs, r.row_w);
  const __m256 border = _mm256_set1_ps(-1.0f);
  const __m256 in_front = _mm256_cmp_ps(pw, _mm256_set1_ps(kMinHomogeneousW), _CMP_GT_OQ);
  const __m256 inv_w = _mm256_div_ps(_mm256_set1_ps(1.0f), pw);
  __m256 u = _mm256_blendv_ps(border, _mm256_mul_ps(px, inv_w), in_front);
  __m256 v = _mm256_blendv_ps(border, _mm256_mul_ps(py, inv_w), in_front);
  // max returns its second operand when the first is NaN: NaN goes to the border.
  u = _mm256_min_ps(_mm256_max_ps(u, border), r.max_u);
  v = _mm256_min_ps(_mm256_max_ps(v, border), r.max_v);
  const __m256 fu = _mm256_floor_ps(u), fv = _mm256_floor_ps(v);
  Footprints f;
  f.ax = _mm256_sub_ps(u, fu);
  f.ay = _mm256_sub_ps(v, fv);
  // The stored block's column and row, clamped to [-2, stored size] (composite_kernels.h).
  const __m256i before = _mm256_set1_epi32(-2);
  const __m256i column = _mm256_min_epi32(
      _mm256_max_epi32(_mm256_sub_epi32(_mm256_cvttps_epi32(fu), r.stored_x), before), r.stored_width);
  const __m256i row = _mm256_min_epi32(
      _mm256_max_epi32(_mm256_sub_epi32(_mm256_cvttps_epi32(fv), r.stored_y), before), r.stored_height);
  const __m256i index = _mm256_add_epi32(_mm256_mullo_epi32(row, r.stride), column);
  _mm256_store_si256(reinterpret_cast<__m256i*>(f.top_left), index);
  return f;
}

// Bilinear samples of two footprints a and b, as [a.bgra | b.bgra].
__m256 sample_pair(const PlaneView& plane, int32_t a, int32_t b, __m256 ax, __m256 ay) {
  const uint16_t* pa = plane.origin + 4 * static_cast<int64_t>(a);
  const uint16_t* pb = plane.origin + 4 * static_cast<int64_t>(b);
  const int64_t below = 4 * plane.stride;
  const __m128i a_top = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pa));
  const __m128i b_top = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pb));
  const __m128i a_bottom = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pa + below));
  const __m128i b_bottom = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pb + below));
  const __m256 tl = _mm256_cvtph_ps(_mm_unpacklo_epi64(a_top, b_top));
  const __m256 tr = _mm256_cvtph_ps(_mm_unpackhi_epi64(a_top, b_top));
  const __m256 bl = _mm256_cvtph_ps(_mm_unpacklo_epi64(a_bottom, b_bottom));
  const __m256 br = _mm256_cvtph_ps(_mm_unpackhi_epi64(a_bottom, b_bottom));
  const __m256 t = _mm256_fmadd_ps(ax, _mm256_sub_ps(tr, tl), tl);
  const __m256 bo = _mm256_fmadd_ps(ax, _mm256_sub_ps(br, bl), bl);
  return _mm256_fmadd_ps(ay, _mm256_sub_ps(bo, t), t);
}

// The same arithmetic for one footprint (an odd pixel at the end of a row).
__m128 sample_one(const PlaneView& plane, int32_t a, float ax_value, float ay_value) {
  const uint16_t* pa = plane.origin + 4 * static_cast<int64_t>(a);
  const int64_t below = 4 * plane.stride;
  const __m128 ax = _mm_set1_ps(ax_value), ay = _mm_set1_ps(ay_value);
  const __m128 tl = _mm_cvtph_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(pa)));
  const __m128 tr = _mm_cvtph_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(pa + 4)));
  const __m128 bl = _mm_cvtph_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(pa + below)));
  const __m128 br = _mm_cvtph_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(pa + below + 4)));
  const __m128 t = _mm_fmadd_ps(ax, _mm_sub_ps(tr, tl), tl);
  const __m128 bo = _mm_fmadd_ps(ax, _mm_sub_ps(br, bl), bl);
  return _mm_fmadd_ps(ay, _mm_sub_ps(bo, t), t);
}

// accum = sample + accum * (1 - sample.alpha), for two pixels or one.
void over_pair(float* accum, __m256 s) {
  const __m256 keep = _mm256_sub_ps(_mm256_set1_ps(1.0f), _mm256_permute_ps(s, 0xFF));
  _mm256_storeu_ps(accum, _mm256_fmadd_ps(_mm256_loadu_ps(accum), keep, s));
}

void over_one(float* accum, __m128 s) {
  const __m128 keep = _mm_sub_ps(_mm_set1_ps(1.0f), _mm_permute_ps(s, 0xFF));
  _mm_storeu_ps(accum, _mm_fmadd_ps(_mm_loadu_ps(accum), keep, s));
}

// Composites the first n (<= 8) footprints of a group over accum.
void composite_group(const PlaneView& plane, const Footprints& f, int n, float* accum) {
  // Lane selectors [2k x4 | 2k+1 x4] spread each pixel's weight over its four channels.
  __m256i lanes = _mm256_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1);
  const __m256i next_pair = _mm256_set1_epi32(2);
  int i = 0;
  for (; i + 2 <= n; i += 2) {
    const __m256 ax = _mm256_permutevar8x32_ps(f.ax, lanes);
    const __m256 ay = _mm256_permutevar8x32_ps(f.ay, lanes);
    over_pair(accum + 4 * i, sample_pair(plane, f.top_left[i], f.top_left[i + 1], ax, ay));
    lanes = _mm256_add_epi32(lanes, next_pair);
  }
  if (i < n) {
    alignas(32) float ax[8], ay[8];
    _mm256_store_ps(ax, f.ax);
    _mm256_store_ps(ay, f.ay);
    over_one(accum + 4 * i, sample_one(plane, f.top_left[i], ax[i], ay[i]));
  }
}

// Bilinear samples of pixels p and p + 1 of a translated row: `top` points at the left
// footprint pixel of p, whose right neighbour is the left one of p + 1, so two unaligned
// loads per row give [left | right] of both pixels.
__m256 shifted_pair(const uint16_t* top, int64_t below, __m256 ax, __m256 ay) {
  const __m256 tl = _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(top)));
  const __m256 tr = _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(top + 4)));
  const __m256 bl = _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(top + below)));
  const __m256 br = _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(top + below + 4)));
  const __m256 t = _mm256_fmadd_ps(ax, _mm256_sub_ps(tr, tl), tl);
  const __m256 bo = _mm256_fmadd_ps(ax, _mm256_sub_ps(br, bl), bl);
  return _mm256_fmadd_ps(ay, _mm256_sub_ps(bo, t), t);
}

__m128i round_to_bytes(__m128 a, __m128 b, __m128 c, __m128 d) {
  const __m128 scale = _mm_set1_ps(255.0f);
  const __m128i ab = _mm_packs_epi32(_mm_cvtps_epi32(_mm_mul_ps(a, scale)),
                                     _mm_cvtps_epi32(_mm_mul_ps(b, scale)));
  const __m128i cd = _mm_packs_epi32(_mm_cvtps_epi32(_mm_mul_ps(c, scale)),
                                     _mm_cvtps_epi32(_mm_mul_ps(d, scale)));
  return _mm_packus_epi16(ab, cd);  // BGRA bytes of four pixels
}

}  // namespace

void warp_over_row(const PlaneView& plane, const InverseHomography& h, int y, int x_begin,
                   int count, float* accum) {
  const RowMap r = row_map(plane, h, y);
  for (int i = 0; i < count; i += 8) {
    const Footprints f = locate(r, x_begin + i);
    composite_group(plane, f, count - i < 8 ? count - i : 8, accum + 4 * i);
  }
}

void shift_over_row(const PlaneView& plane, float du, float dv, int y, int x_begin, int count,
                    float* accum) {
  const ShiftSpan span = shift_span(plane, du, dv, y, x_begin, count);
  if (span.empty) return;
  const int64_t below = 4 * plane.stride;
  const uint16_t* row = plane.origin + span.row * below + 4 * static_cast<int64_t>(span.column_offset);
  const __m256 ax = _mm256_set1_ps(span.ax), ay = _mm256_set1_ps(span.ay);
  int x = span.first;
  for (; x + 1 <= span.last; x += 2)
    over_pair(accum + 4 * (x - x_begin), shifted_pair(row + 4 * static_cast<int64_t>(x), below, ax, ay));
  if (x == span.last)
    over_one(accum + 4 * (x - x_begin), sample_one(plane, static_cast<int32_t>(span.row * plane.stride + x + span.column_offset), span.ax, span.ay));
}

void accum_to_bgr(const float* accum, int count, uint8_t* bgr) {
  const __m128i drop_alpha = _mm_setr_epi8(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1);
  int i = 0;
  for (; i + 4 <= count; i += 4) {
    const float* a = accum + 4 * i;
    const __m128i bytes = _mm_shuffle_epi8(
        round_to_bytes(_mm_loadu_ps(a), _mm_loadu_ps(a + 4), _mm_loadu_ps(a + 8), _mm_loadu_ps(a + 12)),
        drop_alpha);
    uint8_t* out = bgr + 3 * i;
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out), bytes);
    const int last4 = _mm_extract_epi32(bytes, 2);
    std::memcpy(out + 8, &last4, 4);
  }
  for (; i < count; ++i) {
    const __m128 p = _mm_loadu_ps(accum + 4 * i);
    const int bgra = _mm_cvtsi128_si32(round_to_bytes(p, p, p, p));
    std::memcpy(bgr + 3 * i, &bgra, 3);
  }
}

}  // namespace ampi::render::avx2
