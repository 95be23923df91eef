// AVX2 kernels along the channel axis: gated output, concat, squeeze-excite parts
// (channel_scale stays the reference: see kernels/reference/channels.cpp).
// Bodies are lane-generic (kernels/channels_lanes.inl over avx2_channels.h): 8 channels a vector, leftovers scalar.
#include "kernels/x86/avx2_channels.h"
#include "kernels/x86/avx2_kernels.h"
#include "kernels/x86/avx2_math.h"

namespace ampi::avx2 {

#include "kernels/channels_lanes.inl"

void dense(const float* w, const float* bias, int rows, int cols, const float* x,
           ActivationSpec act, float* y) {
  for (int r = 0; r < rows; ++r) {
    const float* row = w + static_cast<int64_t>(r) * cols;
    __m256 acc = _mm256_setzero_ps();
    int j = 0;
    for (; j + 8 <= cols; j += 8) acc = _mm256_fmadd_ps(_mm256_loadu_ps(row + j), _mm256_loadu_ps(x + j), acc);
    float sum = horizontal_sum(acc);
    for (; j < cols; ++j) sum += row[j] * x[j];
    y[r] = ampi::activate((bias ? bias[r] : 0.0f) + sum, act);
  }
}

}  // namespace ampi::avx2
