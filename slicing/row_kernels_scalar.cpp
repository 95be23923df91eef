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

void bilateral_weights(const uint8_t* p, int n, const BilateralPairs& pairs, float* const* weight) {
  for (int h = 0; h < pairs.count; ++h)
    for (int x = 0; x < n; ++x)
      weight[h][x] = pairs.space_weight[h] * pairs.color_weight[std::abs(p[x + pairs.offset[h]] - p[x])];
}

void bilateral_combine(const uint8_t* center, int n, const BilateralTaps& taps, uint8_t* out) {
  for (int x = 0; x < n; ++x) {
    float sum = 0, wsum = 0;
    for (int k = 0; k < taps.count; ++k) {
      const float w = taps.weight[k][x];
      sum += w * static_cast<float>(center[x + taps.offset[k]]);
      wsum += w;
    }
    // The centre tap weighs 1, so wsum >= 1 and the ratio lies in [0, 255].
    out[x] = static_cast<uint8_t>(std::lrint(sum / wsum));
  }
}

void snap_row(const SnapRowInputs& in, int n, float min_step, float margin, float* out, uint8_t* band) {
  for (int x = 0; x < n; ++x) {
    const float lo = in.lo[x], hi = in.hi[x], d = in.disparity[x];
    const float spread = hi - lo;
    const bool edge = spread >= min_step;
    // Explicit fused multiply-adds: the vector variants use the same, so no compiler's
    // contraction choice can make them differ.
    const bool inside = d > std::fma(margin, spread, lo) && d < std::fma(-margin, spread, hi);
    const float fit = std::fma(in.a2[x], in.red[x], std::fma(in.a1[x], in.green[x], std::fma(in.a0[x], in.blue[x], in.b[x] + d)));
    out[x] = edge && inside ? (fit >= (lo + hi) * 0.5f ? hi : lo) : d;
    band[x] = edge ? 255 : 0;
  }
}

}  // namespace ampi::slicing::scalar
