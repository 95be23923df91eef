// NEON 2x resampling kernels: Haar DWT and inverse, nearest and bilinear upscaling.
// Bandwidth-bound; the vectors pay by moving 4 channels per load and store.
#include <algorithm>

#include "kernels/arm/neon_channels.h"
#include "kernels/arm/neon_kernels.h"

namespace ampi::neon {

void haar_dwt(const float* in, int /*h*/, int w, int c, int row_begin, int row_end, float* out) {
  const Channels channels(c);
  const int64_t pixel_pair = 2 * c;
  for (int y = row_begin; y < row_end; ++y) {
    const float* top = in + static_cast<int64_t>(2 * y) * w * c;
    const float* bottom = top + static_cast<int64_t>(w) * c;
    float* dst = out + static_cast<int64_t>(y) * (w / 2) * 4 * c;
    for (int x = 0; x < w / 2; ++x, top += pixel_pair, bottom += pixel_pair, dst += 4 * c)
      channels.each([&](int j, auto v) {
        const float32x4_t x00 = v.load(top + j), x01 = v.load(top + c + j);
        const float32x4_t x10 = v.load(bottom + j), x11 = v.load(bottom + c + j);
        const float32x4_t top_sum = vaddq_f32(x00, x01), top_diff = vsubq_f32(x00, x01);
        const float32x4_t bottom_sum = vaddq_f32(x10, x11), bottom_diff = vsubq_f32(x10, x11);
        v.store(dst + j, vmulq_n_f32(vaddq_f32(top_sum, bottom_sum), 0.5f));
        v.store(dst + c + j, vmulq_n_f32(vaddq_f32(top_diff, bottom_diff), 0.5f));
        v.store(dst + 2 * c + j, vmulq_n_f32(vsubq_f32(top_sum, bottom_sum), 0.5f));
        v.store(dst + 3 * c + j, vmulq_n_f32(vsubq_f32(top_diff, bottom_diff), 0.5f));
      });
  }
}

void haar_idwt(const float* in, int /*h*/, int w, int c, int row_begin, int row_end, float* out) {
  const Channels channels(c);
  for (int y = row_begin; y < row_end; ++y) {
    const float* src = in + static_cast<int64_t>(y) * w * 4 * c;
    float* top = out + static_cast<int64_t>(2 * y) * 2 * w * c;
    float* bottom = top + static_cast<int64_t>(2 * w) * c;
    for (int x = 0; x < w; ++x, src += 4 * c, top += 2 * c, bottom += 2 * c)
      channels.each([&](int j, auto v) {
        const float32x4_t ll = v.load(src + j), lh = v.load(src + c + j);
        const float32x4_t hl = v.load(src + 2 * c + j), hh = v.load(src + 3 * c + j);
        // x00 = (s + t) / 2, x01 = (s - t) / 2 with s = LL + HL, t = LH + HH; the bottom
        // row likewise with the differences.
        const float32x4_t s = vaddq_f32(ll, hl), t = vaddq_f32(lh, hh);
        const float32x4_t sd = vsubq_f32(ll, hl), td = vsubq_f32(lh, hh);
        v.store(top + j, vmulq_n_f32(vaddq_f32(s, t), 0.5f));
        v.store(top + c + j, vmulq_n_f32(vsubq_f32(s, t), 0.5f));
        v.store(bottom + j, vmulq_n_f32(vaddq_f32(sd, td), 0.5f));
        v.store(bottom + c + j, vmulq_n_f32(vsubq_f32(sd, td), 0.5f));
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
        const float32x4_t value = v.load(src + j);
        v.store(top + j, value);
        v.store(top + c + j, value);
        v.store(bottom + j, value);
        v.store(bottom + c + j, value);
      });
  }
}

// Fixed 3/4 : 1/4 weights, vertical blend then horizontal; see resample_avx2.cpp.
static void bilinear_row(const float* near, const float* far, int w, const Channels& channels,
                         int c, float* dst) {
  for (int x = 0; x < w; ++x, dst += 2 * c) {
    const int64_t left = std::max(x - 1, 0) * static_cast<int64_t>(c);
    const int64_t centre = static_cast<int64_t>(x) * c;
    const int64_t right = std::min(x + 1, w - 1) * static_cast<int64_t>(c);
    channels.each([&](int j, auto v) {
      auto column = [&](int64_t at) {
        return vfmaq_n_f32(vmulq_n_f32(v.load(far + at + j), 0.25f), v.load(near + at + j), 0.75f);
      };
      const float32x4_t mid = vmulq_n_f32(column(centre), 0.75f);
      v.store(dst + j, vfmaq_n_f32(mid, column(left), 0.25f));
      v.store(dst + c + j, vfmaq_n_f32(mid, column(right), 0.25f));
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

}  // namespace ampi::neon
