// Scalar depthwise row: the fallback of the scalar table. Output pixel by output pixel,
// taps outside the row skipped by a bounds check, channels innermost.
#include "kernels/reference/reference.h"

namespace ampi::reference {

void depthwise_row(const DepthwiseRowArgs& d) {
  const int c = d.channels;
  for (int ox = 0; ox < d.out_w; ++ox) {
    float* out = d.out + static_cast<int64_t>(ox) * c;
    for (int ch = 0; ch < c; ++ch) out[ch] = d.bias[ch];
    for (int ky = 0; ky < d.kernel_h; ++ky) {
      if (!d.in_rows[ky]) continue;
      for (int kx = 0; kx < d.kernel_w; ++kx) {
        const int ix = ox * d.stride_w - d.pad_left + kx * d.dilation_w;
        if (ix < 0 || ix >= d.in_w) continue;
        const float* in = d.in_rows[ky] + static_cast<int64_t>(ix) * c;
        const float* w = d.weights + static_cast<int64_t>(ky * d.kernel_w + kx) * c;
        for (int ch = 0; ch < c; ++ch) out[ch] += w[ch] * in[ch];
      }
    }
    const float* r = d.residual ? d.residual + static_cast<int64_t>(ox) * c : nullptr;
    for (int ch = 0; ch < c; ++ch) out[ch] = ampi::activate(out[ch], d.act) + (r ? r[ch] : 0.0f);
  }
}

}  // namespace ampi::reference
