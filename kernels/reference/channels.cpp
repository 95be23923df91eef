// Scalar reference kernels that work along the channel axis of NHWC maps.
#include <cmath>

#include "kernels/reference/reference.h"

namespace ampi::reference {

void gated_output(const float* in, int64_t pixels, int c, ActivationSpec act, float* out) {
  for (int64_t p = 0; p < pixels; ++p) {
    const float* feature = in + p * 2 * c;
    const float* gate = feature + c;
    for (int j = 0; j < c; ++j)
      out[p * c + j] = ampi::activate(feature[j], act) / (1.0f + std::exp(-gate[j]));
  }
}

void concat_channels(const float* a, int ca, const float* b, int cb, int64_t pixels, float* out) {
  for (int64_t p = 0; p < pixels; ++p) {
    float* dst = out + p * (ca + cb);
    for (int j = 0; j < ca; ++j) dst[j] = a[p * ca + j];
    for (int j = 0; j < cb; ++j) dst[ca + j] = b[p * cb + j];
  }
}

void channel_sum(const float* in, int64_t pixels, int c, float* sum) {
  for (int j = 0; j < c; ++j) sum[j] = 0.0f;
  for (int64_t p = 0; p < pixels; ++p)
    for (int j = 0; j < c; ++j) sum[j] += in[p * c + j];
}

// No SIMD variant: the compiler vectorises this loop as well as hand-written AVX2 code
// did (measured; the op is bandwidth-bound), so every table keeps it.
void channel_scale(const float* in, int64_t pixels, int c, const float* scale, float* out) {
  for (int64_t p = 0; p < pixels; ++p)
    for (int j = 0; j < c; ++j) out[p * c + j] = in[p * c + j] * scale[j];
}

void dense(const float* w, const float* bias, int rows, int cols, const float* x,
           ActivationSpec act, float* y) {
  for (int r = 0; r < rows; ++r) {
    float acc = bias ? bias[r] : 0.0f;
    for (int j = 0; j < cols; ++j) acc += w[static_cast<int64_t>(r) * cols + j] * x[j];
    y[r] = ampi::activate(acc, act);
  }
}

}  // namespace ampi::reference
