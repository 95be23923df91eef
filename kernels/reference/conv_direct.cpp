#include "kernels/reference/conv_reference.h"

namespace ampi::reference {

void conv2d_direct(const ConvParams& p, const float* in, int in_h, int in_w, const float* weights,
                   const float* bias, const float* residual, float* out) {
  const int out_h = p.out_h(in_h), out_w = p.out_w(in_w);
  const int cin_g = p.in_c / p.groups, cout_g = p.out_c / p.groups;
  for (int oy = 0; oy < out_h; ++oy) {
    for (int ox = 0; ox < out_w; ++ox) {
      for (int oc = 0; oc < p.out_c; ++oc) {
        const int group = oc / cout_g;
        double sum = bias ? bias[oc] : 0.0;
        for (int ky = 0; ky < p.kernel_h; ++ky) {
          const int iy = oy * p.stride_h - p.pad_top + ky * p.dilation_h;
          if (iy < 0 || iy >= in_h) continue;
          for (int kx = 0; kx < p.kernel_w; ++kx) {
            const int ix = ox * p.stride_w - p.pad_left + kx * p.dilation_w;
            if (ix < 0 || ix >= in_w) continue;
            for (int ci = 0; ci < cin_g; ++ci) {
              const float x = in[(static_cast<int64_t>(iy) * in_w + ix) * p.in_c + group * cin_g + ci];
              const float w = weights[((static_cast<int64_t>(oc) * p.kernel_h + ky) * p.kernel_w + kx) * cin_g + ci];
              sum += static_cast<double>(x) * w;
            }
          }
        }
        const int64_t o = (static_cast<int64_t>(oy) * out_w + ox) * p.out_c + oc;
        const float y = ampi::activate(static_cast<float>(sum), p.act);
        out[o] = residual ? y + residual[o] : y;
      }
    }
  }
}

}  // namespace ampi::reference
