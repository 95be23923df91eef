// Scalar reference kernels that halve or double the spatial size of NHWC maps, written
// straight from their definitions (see kernels/ops.h).
#include <algorithm>

#include "kernels/reference/reference.h"

namespace ampi::reference {

void haar_dwt(const float* in, int /*h*/, int w, int c, int row_begin, int row_end, float* out) {
  const int ow = w / 2;
  for (int y = row_begin; y < row_end; ++y)
    for (int x = 0; x < ow; ++x)
      for (int j = 0; j < c; ++j) {
        auto at = [&](int dy, int dx) {
          return in[((static_cast<int64_t>(2 * y + dy) * w) + 2 * x + dx) * c + j];
        };
        const float x00 = at(0, 0), x01 = at(0, 1), x10 = at(1, 0), x11 = at(1, 1);
        float* dst = out + (static_cast<int64_t>(y) * ow + x) * 4 * c + j;
        dst[0] = (x00 + x01 + x10 + x11) / 2;
        dst[c] = (x00 - x01 + x10 - x11) / 2;
        dst[2 * c] = (x00 + x01 - x10 - x11) / 2;
        dst[3 * c] = (x00 - x01 - x10 + x11) / 2;
      }
}

void haar_idwt(const float* in, int /*h*/, int w, int c, int row_begin, int row_end, float* out) {
  for (int y = row_begin; y < row_end; ++y)
    for (int x = 0; x < w; ++x)
      for (int j = 0; j < c; ++j) {
        const float* src = in + (static_cast<int64_t>(y) * w + x) * 4 * c + j;
        const float ll = src[0], lh = src[c], hl = src[2 * c], hh = src[3 * c];
        auto at = [&](int dy, int dx) -> float& {
          return out[((static_cast<int64_t>(2 * y + dy) * 2 * w) + 2 * x + dx) * c + j];
        };
        at(0, 0) = (ll + lh + hl + hh) / 2;
        at(0, 1) = (ll - lh + hl - hh) / 2;
        at(1, 0) = (ll + lh - hl - hh) / 2;
        at(1, 1) = (ll - lh - hl + hh) / 2;
      }
}

void resize2x_nearest(const float* in, int /*h*/, int w, int c, int row_begin, int row_end, float* out) {
  for (int oy = 2 * row_begin; oy < 2 * row_end; ++oy)
    for (int ox = 0; ox < 2 * w; ++ox)
      for (int j = 0; j < c; ++j)
        out[(static_cast<int64_t>(oy) * 2 * w + ox) * c + j] =
            in[(static_cast<int64_t>(oy / 2) * w + ox / 2) * c + j];
}

namespace {

// Where output sample o falls among n input samples, as PyTorch's align_corners=False
// computes it: source = (o + 0.5) / 2 - 0.5, clamped at 0; the right neighbour clamped at
// the last sample.
struct Tap {
  int i0, i1;
  float frac;  // weight of i1
};

Tap bilinear_tap(int o, int n) {
  const float src = std::max(0.0f, (o + 0.5f) * 0.5f - 0.5f);
  const int i0 = static_cast<int>(src);
  return {i0, std::min(i0 + 1, n - 1), src - static_cast<float>(i0)};
}

}  // namespace

void resize2x_bilinear(const float* in, int h, int w, int c, int row_begin, int row_end, float* out) {
  for (int oy = 2 * row_begin; oy < 2 * row_end; ++oy) {
    const Tap ty = bilinear_tap(oy, h);
    for (int ox = 0; ox < 2 * w; ++ox) {
      const Tap tx = bilinear_tap(ox, w);
      for (int j = 0; j < c; ++j) {
        auto at = [&](int y, int x) { return in[(static_cast<int64_t>(y) * w + x) * c + j]; };
        const float top = (1 - tx.frac) * at(ty.i0, tx.i0) + tx.frac * at(ty.i0, tx.i1);
        const float bottom = (1 - tx.frac) * at(ty.i1, tx.i0) + tx.frac * at(ty.i1, tx.i1);
        out[(static_cast<int64_t>(oy) * 2 * w + ox) * c + j] = (1 - ty.frac) * top + ty.frac * bottom;
      }
    }
  }
}

}  // namespace ampi::reference
