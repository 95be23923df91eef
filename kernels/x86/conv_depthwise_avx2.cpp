// AVX2 depthwise row: channels across the 8 lanes (NHWC keeps them contiguous), the
// channel tail through masked loads and stores. Interior columns go in blocks of 8 output
// pixels: each weight vector feeds 8 independent FMA chains (covering the FMA latency),
// and the epilogue activates the 8 results with one dispatch. 3- and 5-wide kernels keep
// a kernel row's weights in registers; with dilation 1 and stride 1 or 2 each input
// column of a block is also loaded only once. Border columns and leftovers go pixel by
// pixel with per-tap bounds checks. Blocks prefetch the next row's new input row.
#include "kernels/conv_epilogue.h"
#include "kernels/x86/avx2_kernels.h"
#include "kernels/x86/avx2_math.h"

namespace ampi::avx2 {
namespace {

constexpr int kLanes = 8;
constexpr int kBlock = 8;  // output pixels per interior block

__m256i lane_mask(int count) {
  return _mm256_cmpgt_epi32(_mm256_set1_epi32(count), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
}

template <bool kPartial>
inline __m256 load(const float* p, __m256i mask) {
  if constexpr (kPartial) return _mm256_maskload_ps(p, mask);
  else return _mm256_loadu_ps(p);
}

template <bool kPartial>
inline void store(float* p, __m256i mask, __m256 v) {
  if constexpr (kPartial) _mm256_maskstore_ps(p, mask, v);
  else _mm256_storeu_ps(p, v);
}

const auto kActivate = [](__m256 v, ActivationSpec a) { return activate(v, a); };

// n output pixels starting at ox, channels [ch, ch + 8): act(acc) (+ residual) stored.
template <bool kPartial, int N>
inline void finish(const DepthwiseRowArgs& d, int ox, int ch, __m256i mask, __m256 (&acc)[N]) {
  activate_tile(acc, d.act, kActivate);
  const int64_t c = d.channels, first = static_cast<int64_t>(ox) * c + ch;
  if (d.residual)
    for (int i = 0; i < N; ++i) acc[i] = _mm256_add_ps(acc[i], load<kPartial>(d.residual + first + i * c, mask));
  for (int i = 0; i < N; ++i) store<kPartial>(d.out + first + i * c, mask, acc[i]);
}

inline void prefetch_block(const DepthwiseRowArgs& d, int64_t first, int64_t pixel_step) {
  if (!d.prefetch_row) return;
  for (int i = 0; i < kBlock; ++i)
    _mm_prefetch(reinterpret_cast<const char*>(d.prefetch_row + first + i * pixel_step), _MM_HINT_T0);
}

// One output pixel at any column, channels [ch, ch + 8): taps outside the row skipped.
template <bool kPartial>
void pixel(const DepthwiseRowArgs& d, int ox, int ch, __m256i mask) {
  const int64_t c = d.channels;
  __m256 acc[1] = {load<kPartial>(d.bias + ch, mask)};
  for (int ky = 0; ky < d.kernel_h; ++ky) {
    if (!d.in_rows[ky]) continue;
    for (int kx = 0; kx < d.kernel_w; ++kx) {
      const int ix = ox * d.stride_w - d.pad_left + kx * d.dilation_w;
      if (ix < 0 || ix >= d.in_w) continue;
      const __m256 w = load<kPartial>(d.weights + (ky * d.kernel_w + kx) * c + ch, mask);
      acc[0] = _mm256_fmadd_ps(w, load<kPartial>(d.in_rows[ky] + ix * c + ch, mask), acc[0]);
    }
  }
  finish<kPartial>(d, ox, ch, mask, acc);
}

// kBlock adjacent interior output pixels starting at ox, channels [ch, ch + 8), any
// kernel width, stride and dilation; kKw is the width when known at compile time
// (weights then stay in registers for a kernel row), 0 for any.
template <bool kPartial, int kKw>
void block(const DepthwiseRowArgs& d, int ox, int ch, __m256i mask) {
  const int kw = kKw > 0 ? kKw : d.kernel_w;
  const int64_t c = d.channels, pixel_step = d.stride_w * c, tap_step = d.dilation_w * c;
  const int64_t first = static_cast<int64_t>(ox * d.stride_w - d.pad_left) * c + ch;
  const float* w = d.weights + ch;
  prefetch_block(d, first, pixel_step);
  const __m256 bias = load<kPartial>(d.bias + ch, mask);
  __m256 acc[kBlock];
  for (int i = 0; i < kBlock; ++i) acc[i] = bias;
  for (int ky = 0; ky < d.kernel_h; ++ky, w += kw * c) {
    if (!d.in_rows[ky]) continue;
    const float* in = d.in_rows[ky] + first;
    if constexpr (kKw > 0) {
      __m256 wv[kKw];
      for (int kx = 0; kx < kKw; ++kx) wv[kx] = load<kPartial>(w + kx * c, mask);
      for (int i = 0; i < kBlock; ++i, in += pixel_step)
        for (int kx = 0; kx < kKw; ++kx) acc[i] = _mm256_fmadd_ps(wv[kx], load<kPartial>(in + kx * tap_step, mask), acc[i]);
    } else {
      for (int kx = 0; kx < kw; ++kx, in += tap_step) {
        const __m256 wv = load<kPartial>(w + kx * c, mask);
        for (int i = 0; i < kBlock; ++i)
          acc[i] = _mm256_fmadd_ps(wv, load<kPartial>(in + i * pixel_step, mask), acc[i]);
      }
    }
  }
  finish<kPartial>(d, ox, ch, mask, acc);
}

// As block(), for dilation 1 and a kernel width and stride known at compile time: each
// input column of the block is loaded once and feeds every (pixel, tap) pair reading it
// (10 loads instead of 24 per kernel row for 3x3 stride 1).
template <bool kPartial, int kKw, int kStride>
void block_shared_columns(const DepthwiseRowArgs& d, int ox, int ch, __m256i mask) {
  constexpr int kColumns = (kBlock - 1) * kStride + kKw;
  const int64_t c = d.channels;
  const int64_t first = static_cast<int64_t>(ox * kStride - d.pad_left) * c + ch;
  const float* w = d.weights + ch;
  prefetch_block(d, first, kStride * c);
  const __m256 bias = load<kPartial>(d.bias + ch, mask);
  __m256 acc[kBlock];
  for (int i = 0; i < kBlock; ++i) acc[i] = bias;
  for (int ky = 0; ky < d.kernel_h; ++ky, w += kKw * c) {
    if (!d.in_rows[ky]) continue;
    __m256 wv[kKw];
    for (int kx = 0; kx < kKw; ++kx) wv[kx] = load<kPartial>(w + kx * c, mask);
    const float* in = d.in_rows[ky] + first;
#pragma GCC unroll 32
    for (int j = 0; j < kColumns; ++j, in += c) {
      const __m256 x = load<kPartial>(in, mask);
#pragma GCC unroll 8
      for (int kx = 0; kx < kKw; ++kx) {
        const int offset = j - kx;  // = i * kStride for the pixel i reading column j at tap kx
        if (offset >= 0 && offset % kStride == 0 && offset / kStride < kBlock)
          acc[offset / kStride] = _mm256_fmadd_ps(wv[kx], x, acc[offset / kStride]);
      }
    }
  }
  finish<kPartial>(d, ox, ch, mask, acc);
}

template <bool kPartial>
using BlockFn = void (*)(const DepthwiseRowArgs&, int, int, __m256i);

template <bool kPartial, int kKw>
BlockFn<kPartial> pick_block(const DepthwiseRowArgs& d) {
  if constexpr (kKw > 0) {
    if (d.dilation_w == 1 && d.stride_w == 1) return block_shared_columns<kPartial, kKw, 1>;
    if (d.dilation_w == 1 && d.stride_w == 2) return block_shared_columns<kPartial, kKw, 2>;
  }
  return block<kPartial, kKw>;
}

template <int kKw>
void row(const DepthwiseRowArgs& d) {
  const int full = d.channels / kLanes * kLanes;
  const __m256i tail = lane_mask(d.channels - full);
  const BlockFn<false> full_block = pick_block<false, kKw>(d);
  const BlockFn<true> tail_block = pick_block<true, kKw>(d);
  const auto one_pixel = [&](int ox) {
    for (int ch = 0; ch < full; ch += kLanes) pixel<false>(d, ox, ch, tail);
    if (full < d.channels) pixel<true>(d, ox, full, tail);
  };
  int ox = 0;
  for (; ox < d.interior_begin; ++ox) one_pixel(ox);
  for (; ox + kBlock <= d.interior_end; ox += kBlock) {
    for (int ch = 0; ch < full; ch += kLanes) full_block(d, ox, ch, tail);
    if (full < d.channels) tail_block(d, ox, full, tail);
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

}  // namespace ampi::avx2
