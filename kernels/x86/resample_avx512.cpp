// AVX-512 2x resampling kernels: Haar DWT and inverse, nearest and bilinear upscaling.
// Bandwidth-bound; the vectors pay by moving 16 channels per load and store.
#include <algorithm>

#include "kernels/x86/avx512_channels.h"
#include "kernels/x86/avx512_kernels.h"

namespace ampi::avx512 {

void haar_dwt(const float* in, int /*h*/, int w, int c, int row_begin, int row_end, float* out) {
  const Channels channels(c);
  const __m512 half = _mm512_set1_ps(0.5f);
  const int64_t pixel_pair = 2 * c;
  for (int y = row_begin; y < row_end; ++y) {
    const float* top = in + static_cast<int64_t>(2 * y) * w * c;
    const float* bottom = top + static_cast<int64_t>(w) * c;
    float* dst = out + static_cast<int64_t>(y) * (w / 2) * 4 * c;
    for (int x = 0; x < w / 2; ++x, top += pixel_pair, bottom += pixel_pair, dst += 4 * c)
      channels.each([&](int j, auto v) {
        const __m512 x00 = v.load(top + j), x01 = v.load(top + c + j);
        const __m512 x10 = v.load(bottom + j), x11 = v.load(bottom + c + j);
        const __m512 top_sum = _mm512_add_ps(x00, x01), top_diff = _mm512_sub_ps(x00, x01);
        const __m512 bottom_sum = _mm512_add_ps(x10, x11), bottom_diff = _mm512_sub_ps(x10, x11);
        v.store(dst + j, _mm512_mul_ps(_mm512_add_ps(top_sum, bottom_sum), half));
        v.store(dst + c + j, _mm512_mul_ps(_mm512_add_ps(top_diff, bottom_diff), half));
        v.store(dst + 2 * c + j, _mm512_mul_ps(_mm512_sub_ps(top_sum, bottom_sum), half));
        v.store(dst + 3 * c + j, _mm512_mul_ps(_mm512_sub_ps(top_diff, bottom_diff), half));
      });
  }
}

void haar_idwt(const float* in, int /*h*/, int w, int c, int row_begin, int row_end, float* out) {
  const Channels channels(c);
  const __m512 half = _mm512_set1_ps(0.5f);
  for (int y = row_begin; y < row_end; ++y) {
    const float* src = in + static_cast<int64_t>(y) * w * 4 * c;
    float* top = out + static_cast<int64_t>(2 * y) * 2 * w * c;
    float* bottom = top + static_cast<int64_t>(2 * w) * c;
    for (int x = 0; x < w; ++x, src += 4 * c, top += 2 * c, bottom += 2 * c)
      channels.each([&](int j, auto v) {
        const __m512 ll = v.load(src + j), lh = v.load(src + c + j);
        const __m512 hl = v.load(src + 2 * c + j), hh = v.load(src + 3 * c + j);
        // x00 = (s + t) / 2, x01 = (s - t) / 2 with s = LL + HL, t = LH + HH; the bottom
        // row likewise with the differences.
        const __m512 s = _mm512_add_ps(ll, hl), t = _mm512_add_ps(lh, hh);
        const __m512 sd = _mm512_sub_ps(ll, hl), td = _mm512_sub_ps(lh, hh);
        v.store(top + j, _mm512_mul_ps(_mm512_add_ps(s, t), half));
        v.store(top + c + j, _mm512_mul_ps(_mm512_sub_ps(s, t), half));
        v.store(bottom + j, _mm512_mul_ps(_mm512_add_ps(sd, td), half));
        v.store(bottom + c + j, _mm512_mul_ps(_mm512_sub_ps(sd, td), half));
      });
  }
}

void resize2x_nearest(const float* in, int /*h*/, int w, int c, int row_begin, int row_end, float* out) {
  const Channels channels(c);
  for (int y = row_begin; y < row_end; ++y) {
    const float* src = in + static_cast<int64_t>(y) * w * c;
    float* top = out + static_cast<int64_t>(2 * y) * 2 * w * c;
    float* bottom = top + static_cast<int64_t>(2 * w) * c;
    for (int x = 0; x < w; ++x, src += c, top += 2 * c, bottom += 2 * c)
      channels.each([&](int j, auto v) {
        const __m512 value = v.load(src + j);
        v.store(top + j, value);
        v.store(top + c + j, value);
        v.store(bottom + j, value);
        v.store(bottom + c + j, value);
      });
  }
}

// With half-pixel centres a 2x upscale has fixed weights: output 2i blends input i and
// i-1 by 3/4 : 1/4, output 2i+1 blends i and i+1, neighbours clamped at the border. One
// output row is the vertical blend `near * 3/4 + far * 1/4` of two input rows, then the
// same blend horizontally.
static void bilinear_row(const float* near, const float* far, int w, const Channels& channels,
                         int c, float* dst) {
  const __m512 three_quarters = _mm512_set1_ps(0.75f), quarter = _mm512_set1_ps(0.25f);
  for (int x = 0; x < w; ++x, dst += 2 * c) {
    const int64_t left = std::max(x - 1, 0) * static_cast<int64_t>(c);
    const int64_t centre = static_cast<int64_t>(x) * c;
    const int64_t right = std::min(x + 1, w - 1) * static_cast<int64_t>(c);
    channels.each([&](int j, auto v) {
      auto column = [&](int64_t at) {
        return _mm512_fmadd_ps(v.load(near + at + j), three_quarters,
                               _mm512_mul_ps(v.load(far + at + j), quarter));
      };
      const __m512 mid = _mm512_mul_ps(column(centre), three_quarters);
      v.store(dst + j, _mm512_fmadd_ps(column(left), quarter, mid));
      v.store(dst + c + j, _mm512_fmadd_ps(column(right), quarter, mid));
    });
  }
}

void resize2x_bilinear(const float* in, int h, int w, int c, int row_begin, int row_end, float* out) {
  const Channels channels(c);
  const int64_t in_row = static_cast<int64_t>(w) * c;
  for (int y = row_begin; y < row_end; ++y) {
    const float* row = in + y * in_row;
    float* top = out + static_cast<int64_t>(2 * y) * 2 * in_row;
    bilinear_row(row, in + std::max(y - 1, 0) * in_row, w, channels, c, top);
    bilinear_row(row, in + std::min(y + 1, h - 1) * in_row, w, channels, c, top + 2 * in_row);
  }
}

}  // namespace ampi::avx512
