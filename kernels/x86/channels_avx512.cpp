// AVX-512 kernels along the channel axis: gated output, concat, squeeze-excite parts
// (channel_scale stays the reference: see kernels/reference/channels.cpp).
#include "kernels/x86/avx512_channels.h"
#include "kernels/x86/avx512_kernels.h"
#include "kernels/x86/avx512_math.h"

namespace ampi::avx512 {

void gated_output(const float* in, int64_t pixels, int c, ActivationSpec act, float* out) {
  const Channels channels(c);
  for (int64_t p = 0; p < pixels; ++p) {
    const float* feature = in + p * 2 * c;
    const float* gate = feature + c;
    float* dst = out + p * c;
    channels.each([&](int j, auto v) {
      v.store(dst + j, _mm512_mul_ps(activate(v.load(feature + j), act), sigmoid(v.load(gate + j))));
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
    __m512 acc = _mm512_setzero_ps();
    for (int64_t p = 0; p < pixels; ++p) acc = _mm512_add_ps(acc, v.load(in + p * c + j));
    v.store(sum + j, acc);
  });
}

void dense(const float* w, const float* bias, int rows, int cols, const float* x,
           ActivationSpec act, float* y) {
  const Channels channels(cols);
  for (int r = 0; r < rows; ++r) {
    const float* row = w + static_cast<int64_t>(r) * cols;
    __m512 acc = _mm512_setzero_ps();
    channels.each([&](int j, auto v) { acc = _mm512_fmadd_ps(v.load(row + j), v.load(x + j), acc); });
    y[r] = ampi::activate((bias ? bias[r] : 0.0f) + _mm512_reduce_add_ps(acc), act);
  }
}

}  // namespace ampi::avx512
