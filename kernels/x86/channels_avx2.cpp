// AVX2 kernels along the channel axis: gated output, concat, squeeze-excite parts
// (channel_scale stays the reference: see kernels/reference/channels.cpp).
// Bodies are lane-generic (see avx2_channels.h): 8 channels a vector, leftovers scalar.
#include "kernels/x86/avx2_channels.h"
#include "kernels/x86/avx2_kernels.h"
#include "kernels/x86/avx2_math.h"

namespace ampi::avx2 {

void gated_output(const float* in, int64_t pixels, int c, ActivationSpec act, float* out) {
  const Channels channels(c);
  for (int64_t p = 0; p < pixels; ++p) {
    const float* feature = in + p * 2 * c;
    const float* gate = feature + c;
    float* dst = out + p * c;
    channels.each([&](int j, auto lane) {
      lane.store(dst + j, times(activate(lane.load(feature + j), act), sigmoid(lane.load(gate + j))));
    });
  }
}

void concat_channels(const float* a, int ca, const float* b, int cb, int64_t pixels, float* out) {
  for (int64_t p = 0; p < pixels; ++p) {
    float* dst = out + p * (ca + cb);
    copy_floats(a + p * ca, ca, dst);
    copy_floats(b + p * cb, cb, dst + ca);
  }
}

// Channel blocks outermost: each block's running sum stays in a register, and adding in
// pixel order gives the reference's result bit for bit.
void channel_sum(const float* in, int64_t pixels, int c, float* sum) {
  Channels(c).each([&](int j, auto lane) {
    auto acc = lane.splat(0.0f);
    for (int64_t p = 0; p < pixels; ++p) acc = plus(acc, lane.load(in + p * c + j));
    lane.store(sum + j, acc);
  });
}

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
