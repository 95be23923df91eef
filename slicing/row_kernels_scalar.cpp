// The scalar references of the slicer's row kernels (see row_kernels.h).
#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "slicing/row_kernels.h"

namespace ampi::slicing::scalar {

void range_row(const float* in, int n, ValueRange& range) {
  for (int x = 0; x < n; ++x) {
    range.finite = range.finite && std::isfinite(in[x]);
    range.lo = std::min(range.lo, in[x]);
    range.hi = std::max(range.hi, in[x]);
  }
}

void normalize_row(const float* in, int n, double lo, double scale, float* value, uint8_t* level) {
  for (int x = 0; x < n; ++x) {
    value[x] = static_cast<float>(std::min((in[x] - lo) * scale, 255.0));
    level[x] = static_cast<uint8_t>(std::nearbyint(value[x]));  // the default mode: ties to even
  }
}

void bilateral_row(const uint8_t* center, int width, const BilateralTaps& taps, uint8_t* out) {
  for (int x = 0; x < width; ++x) {
    const uint8_t* c = center + x;
    float sum = 0, wsum = 0;
    for (int k = 0; k < taps.count; ++k) {
      const int v = c[taps.offset[k]];
      const float w = taps.space_weight[k] * taps.color_weight[std::abs(v - c[0])];
      sum += w * static_cast<float>(v);
      wsum += w;
    }
    // The centre tap has weight 1 * 1, so wsum >= 1 and the ratio lies in [0, 255].
    out[x] = static_cast<uint8_t>(std::lrint(sum / wsum));
  }
}

}  // namespace ampi::slicing::scalar
