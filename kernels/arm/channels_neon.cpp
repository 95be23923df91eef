// NEON kernels along the channel axis: gated output, concat, squeeze-excite parts.
#include "kernels/arm/neon_channels.h"
#include "kernels/arm/neon_kernels.h"
#include "kernels/arm/neon_math.h"

namespace ampi::neon {

void gated_output(const float* in, int64_t pixels, int c, ActivationSpec act, float* out) {
  const Channels channels(c);
  for (int64_t p = 0; p < pixels; ++p) {
    const float* feature = in + p * 2 * c;
    const float* gate = feature + c;
    float* dst = out + p * c;
    channels.each([&](int j, auto v) {
      v.store(dst + j, vmulq_f32(activate(v.load(feature + j), act), sigmoid(v.load(gate + j))));
    });
  }
}

void concat_channels(const float* a, int ca, const float* b, int cb, int64_t pixels, float* out) {
  const Channels channels_a(ca), channels_b(cb);
  for (int64_t p = 0; p < pixels; ++p) {
    const float* src_a = a + p * ca;
    const float* src_b = b + p * cb;
    float* dst = out + p * (ca + cb);
    channels_a.each([&](int j, auto v) { v.store(dst + j, v.load(src_a + j)); });
    channels_b.each([&](int j, auto v) { v.store(dst + ca + j, v.load(src_b + j)); });
  }
}

// Channel blocks outermost: each block's running sum stays in a register, and adding in
// pixel order gives the reference's result bit for bit.
void channel_sum(const float* in, int64_t pixels, int c, float* sum) {
  Channels(c).each([&](int j, auto v) {
    float32x4_t acc = vdupq_n_f32(0.0f);
    for (int64_t p = 0; p < pixels; ++p) acc = vaddq_f32(acc, v.load(in + p * c + j));
    v.store(sum + j, acc);
  });
}

void channel_scale(const float* in, int64_t pixels, int c, const float* scale, float* out) {
  const Channels channels(c);
  for (int64_t p = 0; p < pixels; ++p)
    channels.each([&](int j, auto v) {
      v.store(out + p * c + j, vmulq_f32(v.load(in + p * c + j), v.load(scale + j)));
    });
}

void dense(const float* w, const float* bias, int rows, int cols, const float* x,
           ActivationSpec act, float* y) {
  const Channels channels(cols);
  for (int r = 0; r < rows; ++r) {
    const float* row = w + static_cast<int64_t>(r) * cols;
    float32x4_t acc = vdupq_n_f32(0.0f);
    channels.each([&](int j, auto v) { acc = vfmaq_f32(acc, v.load(row + j), v.load(x + j)); });
    y[r] = ampi::activate((bias ? bias[r] : 0.0f) + vaddvq_f32(acc), act);
  }
}

}  // namespace ampi::neon
