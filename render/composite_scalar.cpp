// The scalar reference of the compositor kernels: one pixel at a time, the formulas the
// SIMD variants vectorise.
#include <algorithm>
#include <cmath>

#include "engine/half.h"
#include "render/composite_kernels.h"

namespace ampi::render::scalar {
namespace {

struct Bgra {
  float c[4];
};

Bgra load_pixel(const uint16_t* p) {
  return {{half_to_float(p[0]), half_to_float(p[1]), half_to_float(p[2]), half_to_float(p[3])}};
}

// Clamps a layer coordinate to [-1, hi]; NaN (a degenerate homography) goes to -1.
float clamp_to_border(float c, float hi) { return c >= -1.0f ? std::min(c, hi) : -1.0f; }

// The stored block's column (or row) of a footprint starting at layer column `layer`:
// clamped to [-2, stored], where a footprint reads only the block's transparent border.
int64_t stored_index(float layer, int start, int stored) {
  return std::min<int64_t>(std::max<int64_t>(static_cast<int64_t>(layer) - start, -2), stored);
}

// Bilinear sample of the padded layer at (u, v), already clamped to [-1, w] x [-1, h].
Bgra sample(const PlaneView& plane, float u, float v) {
  const float fu = std::floor(u), fv = std::floor(v);
  const float ax = u - fu, ay = v - fv;
  const int64_t column = stored_index(fu, plane.stored_x, plane.stored_width);
  const int64_t row = stored_index(fv, plane.stored_y, plane.stored_height);
  const uint16_t* top = plane.origin + 4 * (row * plane.stride + column);
  const uint16_t* bottom = top + 4 * plane.stride;
  const Bgra tl = load_pixel(top), tr = load_pixel(top + 4);
  const Bgra bl = load_pixel(bottom), br = load_pixel(bottom + 4);
  Bgra s;
  for (int k = 0; k < 4; ++k) {
    const float t = tl.c[k] + ax * (tr.c[k] - tl.c[k]);
    const float b = bl.c[k] + ax * (br.c[k] - bl.c[k]);
    s.c[k] = t + ay * (b - t);
  }
  return s;
}

}  // namespace

void warp_over_row(const PlaneView& plane, const InverseHomography& h, int y, int x_begin,
                   int count, float* accum) {
  const float* m = h.m;
  const float fy = static_cast<float>(y);
  const float row_x = m[1] * fy + m[2], row_y = m[4] * fy + m[5], row_w = m[7] * fy + m[8];
  const float max_u = static_cast<float>(plane.width), max_v = static_cast<float>(plane.height);
  for (int i = 0; i < count; ++i) {
    const float x = static_cast<float>(x_begin + i);
    const float px = m[0] * x + row_x, py = m[3] * x + row_y, pw = m[6] * x + row_w;
    float u = -1.0f, v = -1.0f;  // behind the camera: the transparent border
    if (pw > kMinHomogeneousW) {
      const float inv_w = 1.0f / pw;
      u = px * inv_w;
      v = py * inv_w;
    }
    const Bgra s = sample(plane, clamp_to_border(u, max_u), clamp_to_border(v, max_v));
    float* out = accum + 4 * i;
    const float keep = 1.0f - s.c[3];
    for (int k = 0; k < 4; ++k) out[k] = out[k] * keep + s.c[k];
  }
}

// The reference is the general warp with the translation's matrix: with its zeros and
// ones the warp computes u = x + du and v = y + dv exactly.
void shift_over_row(const PlaneView& plane, float du, float dv, int y, int x_begin, int count,
                    float* accum) {
  warp_over_row(plane, InverseHomography{{1, 0, du, 0, 1, dv, 0, 0, 1}}, y, x_begin, count, accum);
}

void accum_to_bgr(const float* accum, int count, uint8_t* bgr) {
  for (int i = 0; i < count; ++i)
    for (int k = 0; k < 3; ++k) {
      const float v = std::nearbyint(accum[4 * i + k] * 255.0f);
      bgr[3 * i + k] = static_cast<uint8_t>(std::min(255.0f, std::max(0.0f, v)));
    }
}

}  // namespace ampi::render::scalar
