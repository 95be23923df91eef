// NEON kernels along the channel axis: gated output, concat, squeeze-excite parts
// (channel_scale stays the reference: see kernels/reference/channels.cpp).
// Bodies are lane-generic (kernels/channels_lanes.inl over neon_channels.h): 4 channels a vector, leftovers scalar.
#include "kernels/arm/neon_channels.h"
#include "kernels/arm/neon_kernels.h"
#include "kernels/arm/neon_math.h"

namespace ampi::neon {

#include "kernels/channels_lanes.inl"

void dense(const float* w, const float* bias, int rows, int cols, const float* x,
           ActivationSpec act, float* y) {
  for (int r = 0; r < rows; ++r) {
    const float* row = w + static_cast<int64_t>(r) * cols;
    float32x4_t acc = vdupq_n_f32(0.0f);
    int j = 0;
    for (; j + 4 <= cols; j += 4) acc = vfmaq_f32(acc, vld1q_f32(row + j), vld1q_f32(x + j));
    float sum = vaddvq_f32(acc);
    for (; j < cols; ++j) sum += row[j] * x[j];
    y[r] = ampi::activate((bias ? bias[r] : 0.0f) + sum, act);
  }
}

}  // namespace ampi::neon
