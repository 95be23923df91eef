// NEON depthwise row, the same scheme as the AVX2 one (conv_depthwise_avx2.cpp) with 4
// lanes: channels across the lanes; NEON has no masked loads, so the channel tail
// (channels % 4) runs a scalar loop. Interior columns go in blocks of 8 output pixels,
// each weight vector feeding 8 independent FMA chains; with dilation 1 and stride 1 or 2
// each input column of a block is loaded once. Border columns and leftovers go pixel by
// pixel with per-tap bounds checks.
#include "kernels/arm/neon_kernels.h"
#include "kernels/arm/neon_math.h"
#include "kernels/conv_epilogue.h"

namespace ampi::neon {
namespace {

constexpr int kLanes = 4;
constexpr int kBlock = 8;  // output pixels per interior block

const auto kActivate = [](float32x4_t v, ActivationSpec a) { return activate(v, a); };

// N output pixels starting at ox, channels [ch, ch + 4): act(acc) (+ residual).
template <int N>
inline void finish(const DepthwiseRowArgs& d, int ox, int ch, float32x4_t (&acc)[N]) {
  activate_tile(acc, d.act, kActivate);
  const int64_t c = d.channels, first = static_cast<int64_t>(ox) * c + ch;
  if (d.residual)
    for (int i = 0; i < N; ++i) acc[i] = vaddq_f32(acc[i], vld1q_f32(d.residual + first + i * c));
  for (int i = 0; i < N; ++i) vst1q_f32(d.out + first + i * c, acc[i]);
}

inline void prefetch_block(const DepthwiseRowArgs& d, int64_t first, int64_t pixel_step) {
  if (!d.prefetch_row) return;
  for (int i = 0; i < kBlock; ++i) __builtin_prefetch(d.prefetch_row + first + i * pixel_step);
}

bool tap_inside(const DepthwiseRowArgs& d, int ox, int kx, int& ix) {
  ix = ox * d.stride_w - d.pad_left + kx * d.dilation_w;
  return ix >= 0 && ix < d.in_w;
}

// One output pixel at any column, channels [ch, ch + 4): taps outside the row skipped.
void pixel(const DepthwiseRowArgs& d, int ox, int ch) {
  const int64_t c = d.channels;
  float32x4_t acc[1] = {vld1q_f32(d.bias + ch)};
  for (int ky = 0; ky < d.kernel_h; ++ky) {
    if (!d.in_rows[ky]) continue;
    for (int kx = 0; kx < d.kernel_w; ++kx) {
      int ix;
      if (!tap_inside(d, ox, kx, ix)) continue;
      const float32x4_t w = vld1q_f32(d.weights + (ky * d.kernel_w + kx) * c + ch);
      acc[0] = vfmaq_f32(acc[0], w, vld1q_f32(d.in_rows[ky] + ix * c + ch));
    }
  }
  finish(d, ox, ch, acc);
}

// One output pixel, the channels [first, channels) that do not fill a vector.
void pixel_tail(const DepthwiseRowArgs& d, int ox, int first) {
  const int64_t c = d.channels;
  for (int ch = first; ch < d.channels; ++ch) {
    float acc = d.bias[ch];
    for (int ky = 0; ky < d.kernel_h; ++ky) {
      if (!d.in_rows[ky]) continue;
      for (int kx = 0; kx < d.kernel_w; ++kx) {
        int ix;
        if (tap_inside(d, ox, kx, ix))
          acc += d.weights[(ky * d.kernel_w + kx) * c + ch] * d.in_rows[ky][ix * c + ch];
      }
    }
    const int64_t o = ox * c + ch;
    d.out[o] = ampi::activate(acc, d.act) + (d.residual ? d.residual[o] : 0.0f);
  }
}

// kBlock adjacent interior output pixels starting at ox, channels [ch, ch + 4), any
// kernel width, stride and dilation; kKw is the width when known at compile time
// (weights then stay in registers for a kernel row), 0 for any.
template <int kKw>
void block(const DepthwiseRowArgs& d, int ox, int ch) {
  const int kw = kKw > 0 ? kKw : d.kernel_w;
  const int64_t c = d.channels, pixel_step = d.stride_w * c, tap_step = d.dilation_w * c;
  const int64_t first = static_cast<int64_t>(ox * d.stride_w - d.pad_left) * c + ch;
  const float* w = d.weights + ch;
  prefetch_block(d, first, pixel_step);
  const float32x4_t bias = vld1q_f32(d.bias + ch);
  float32x4_t acc[kBlock];
  for (int i = 0; i < kBlock; ++i) acc[i] = bias;
  for (int ky = 0; ky < d.kernel_h; ++ky, w += kw * c) {
    if (!d.in_rows[ky]) continue;
    const float* in = d.in_rows[ky] + first;
    if constexpr (kKw > 0) {
      float32x4_t wv[kKw];
      for (int kx = 0; kx < kKw; ++kx) wv[kx] = vld1q_f32(w + kx * c);
      for (int i = 0; i < kBlock; ++i, in += pixel_step)
        for (int kx = 0; kx < kKw; ++kx) acc[i] = vfmaq_f32(acc[i], wv[kx], vld1q_f32(in + kx * tap_step));
    } else {
      for (int kx = 0; kx < kw; ++kx, in += tap_step) {
        const float32x4_t wv = vld1q_f32(w + kx * c);
        for (int i = 0; i < kBlock; ++i) acc[i] = vfmaq_f32(acc[i], wv, vld1q_f32(in + i * pixel_step));
      }
    }
  }
  finish(d, ox, ch, acc);
}

// As block(), for dilation 1 and a kernel width and stride known at compile time: each
// input column of the block is loaded once and feeds every (pixel, tap) pair reading it.
template <int kKw, int kStride>
void block_shared_columns(const DepthwiseRowArgs& d, int ox, int ch) {
  constexpr int kColumns = (kBlock - 1) * kStride + kKw;
  const int64_t c = d.channels;
  const int64_t first = static_cast<int64_t>(ox * kStride - d.pad_left) * c + ch;
  const float* w = d.weights + ch;
  prefetch_block(d, first, kStride * c);
  const float32x4_t bias = vld1q_f32(d.bias + ch);
  float32x4_t acc[kBlock];
  for (int i = 0; i < kBlock; ++i) acc[i] = bias;
  for (int ky = 0; ky < d.kernel_h; ++ky, w += kKw * c) {
    if (!d.in_rows[ky]) continue;
    float32x4_t wv[kKw];
    for (int kx = 0; kx < kKw; ++kx) wv[kx] = vld1q_f32(w + kx * c);
    const float* in = d.in_rows[ky] + first;
#pragma GCC unroll 32
    for (int j = 0; j < kColumns; ++j, in += c) {
      const float32x4_t x = vld1q_f32(in);
#pragma GCC unroll 8
      for (int kx = 0; kx < kKw; ++kx) {
        const int offset = j - kx;  // = i * kStride for the pixel i reading column j at tap kx
        if (offset >= 0 && offset % kStride == 0 && offset / kStride < kBlock)
          acc[offset / kStride] = vfmaq_f32(acc[offset / kStride], wv[kx], x);
      }
    }
  }
  finish(d, ox, ch, acc);
}

using BlockFn = void (*)(const DepthwiseRowArgs&, int, int);

template <int kKw>
BlockFn pick_block(const DepthwiseRowArgs& d) {
  if constexpr (kKw > 0) {
    if (d.dilation_w == 1 && d.stride_w == 1) return block_shared_columns<kKw, 1>;
    if (d.dilation_w == 1 && d.stride_w == 2) return block_shared_columns<kKw, 2>;
  }
  return block<kKw>;
}

template <int kKw>
void row(const DepthwiseRowArgs& d) {
  const int full = d.channels / kLanes * kLanes;
  const BlockFn block_fn = pick_block<kKw>(d);
  const auto one_pixel = [&](int ox) {
    for (int ch = 0; ch < full; ch += kLanes) pixel(d, ox, ch);
    pixel_tail(d, ox, full);
  };
  int ox = 0;
  for (; ox < d.interior_begin; ++ox) one_pixel(ox);
  for (; ox + kBlock <= d.interior_end; ox += kBlock) {
    for (int ch = 0; ch < full; ch += kLanes) block_fn(d, ox, ch);
    for (int i = 0; i < kBlock; ++i) pixel_tail(d, ox + i, full);
  }
  for (; ox < d.out_w; ++ox) one_pixel(ox);
}

}  // namespace

void depthwise_row(const DepthwiseRowArgs& d) {
  switch (d.kernel_w) {
    case 3: return row<3>(d);
    case 5: return row<5>(d);
    default: return row<0>(d);
  }
}

}  // namespace ampi::neon
