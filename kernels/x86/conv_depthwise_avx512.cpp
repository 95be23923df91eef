// AVX-512 depthwise row, the same scheme as the AVX2 one (conv_depthwise_avx2.cpp) with
// 16 lanes: channels across the lanes, the channel tail through masked loads and stores
// (a full vector uses an all-ones mask: same speed, one code path). Interior columns go
// in blocks of 8 output pixels, each weight vector feeding 8 independent FMA chains; with
// dilation 1 and stride 1 or 2 each input column of a block is loaded once. Border
// columns and leftovers go pixel by pixel with per-tap bounds checks.
#include "kernels/conv_epilogue.h"
#include "kernels/x86/avx512_kernels.h"
#include "kernels/x86/avx512_math.h"

namespace ampi::avx512 {
namespace {

constexpr int kLanes = 16;
constexpr int kBlock = 8;  // output pixels per interior block

inline __mmask16 lane_mask(int count) {
  return count >= 16 ? static_cast<__mmask16>(0xffff) : static_cast<__mmask16>((1u << count) - 1u);
}

const auto kActivate = [](__m512 v, ActivationSpec a) { return activate(v, a); };

// N output pixels starting at ox, channels [ch, ch + 16) under m: act(acc) (+ residual).
template <int N>
inline void finish(const DepthwiseRowArgs& d, int ox, int ch, __mmask16 m, __m512 (&acc)[N]) {
  activate_tile(acc, d.act, kActivate);
  const int64_t c = d.channels, first = static_cast<int64_t>(ox) * c + ch;
  if (d.residual)
    for (int i = 0; i < N; ++i) acc[i] = _mm512_add_ps(acc[i], _mm512_maskz_loadu_ps(m, d.residual + first + i * c));
  for (int i = 0; i < N; ++i) _mm512_mask_storeu_ps(d.out + first + i * c, m, acc[i]);
}

inline void prefetch_block(const DepthwiseRowArgs& d, int64_t first, int64_t pixel_step) {
  if (!d.prefetch_row) return;
  for (int i = 0; i < kBlock; ++i)
    _mm_prefetch(reinterpret_cast<const char*>(d.prefetch_row + first + i * pixel_step), _MM_HINT_T0);
}

// One output pixel at any column, channels [ch, ch + 16) under m: taps outside the row
// skipped.
void pixel(const DepthwiseRowArgs& d, int ox, int ch, __mmask16 m) {
  const int64_t c = d.channels;
  __m512 acc[1] = {_mm512_maskz_loadu_ps(m, d.bias + ch)};
  for (int ky = 0; ky < d.kernel_h; ++ky) {
    if (!d.in_rows[ky]) continue;
    for (int kx = 0; kx < d.kernel_w; ++kx) {
      const int ix = ox * d.stride_w - d.pad_left + kx * d.dilation_w;
      if (ix < 0 || ix >= d.in_w) continue;
      const __m512 w = _mm512_maskz_loadu_ps(m, d.weights + (ky * d.kernel_w + kx) * c + ch);
      acc[0] = _mm512_fmadd_ps(w, _mm512_maskz_loadu_ps(m, d.in_rows[ky] + ix * c + ch), acc[0]);
    }
  }
  finish(d, ox, ch, m, acc);
}

// kBlock adjacent interior output pixels starting at ox, any kernel width, stride and
// dilation; kKw is the width when known at compile time (weights then stay in registers
// for a kernel row), 0 for any.
template <int kKw>
void block(const DepthwiseRowArgs& d, int ox, int ch, __mmask16 m) {
  const int kw = kKw > 0 ? kKw : d.kernel_w;
  const int64_t c = d.channels, pixel_step = d.stride_w * c, tap_step = d.dilation_w * c;
  const int64_t first = static_cast<int64_t>(ox * d.stride_w - d.pad_left) * c + ch;
  const float* w = d.weights + ch;
  prefetch_block(d, first, pixel_step);
  const __m512 bias = _mm512_maskz_loadu_ps(m, d.bias + ch);
  __m512 acc[kBlock];
  for (int i = 0; i < kBlock; ++i) acc[i] = bias;
  for (int ky = 0; ky < d.kernel_h; ++ky, w += kw * c) {
    if (!d.in_rows[ky]) continue;
    const float* in = d.in_rows[ky] + first;
    if constexpr (kKw > 0) {
      __m512 wv[kKw];
      for (int kx = 0; kx < kKw; ++kx) wv[kx] = _mm512_maskz_loadu_ps(m, w + kx * c);
      for (int i = 0; i < kBlock; ++i, in += pixel_step)
        for (int kx = 0; kx < kKw; ++kx)
          acc[i] = _mm512_fmadd_ps(wv[kx], _mm512_maskz_loadu_ps(m, in + kx * tap_step), acc[i]);
    } else {
      for (int kx = 0; kx < kw; ++kx, in += tap_step) {
        const __m512 wv = _mm512_maskz_loadu_ps(m, w + kx * c);
        for (int i = 0; i < kBlock; ++i)
          acc[i] = _mm512_fmadd_ps(wv, _mm512_maskz_loadu_ps(m, in + i * pixel_step), acc[i]);
      }
    }
  }
  finish(d, ox, ch, m, acc);
}

// As block(), for dilation 1 and a kernel width and stride known at compile time: each
// input column of the block is loaded once and feeds every (pixel, tap) pair reading it.
template <int kKw, int kStride>
void block_shared_columns(const DepthwiseRowArgs& d, int ox, int ch, __mmask16 m) {
  constexpr int kColumns = (kBlock - 1) * kStride + kKw;
  const int64_t c = d.channels;
  const int64_t first = static_cast<int64_t>(ox * kStride - d.pad_left) * c + ch;
  const float* w = d.weights + ch;
  prefetch_block(d, first, kStride * c);
  const __m512 bias = _mm512_maskz_loadu_ps(m, d.bias + ch);
  __m512 acc[kBlock];
  for (int i = 0; i < kBlock; ++i) acc[i] = bias;
  for (int ky = 0; ky < d.kernel_h; ++ky, w += kKw * c) {
    if (!d.in_rows[ky]) continue;
    __m512 wv[kKw];
    for (int kx = 0; kx < kKw; ++kx) wv[kx] = _mm512_maskz_loadu_ps(m, w + kx * c);
    const float* in = d.in_rows[ky] + first;
#pragma GCC unroll 32
    for (int j = 0; j < kColumns; ++j, in += c) {
      const __m512 x = _mm512_maskz_loadu_ps(m, in);
#pragma GCC unroll 8
      for (int kx = 0; kx < kKw; ++kx) {
        const int offset = j - kx;  // = i * kStride for the pixel i reading column j at tap kx
        if (offset >= 0 && offset % kStride == 0 && offset / kStride < kBlock)
          acc[offset / kStride] = _mm512_fmadd_ps(wv[kx], x, acc[offset / kStride]);
      }
    }
  }
  finish(d, ox, ch, m, acc);
}

using BlockFn = void (*)(const DepthwiseRowArgs&, int, int, __mmask16);

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
  const BlockFn block_fn = pick_block<kKw>(d);
  int ox = 0;
  for (; ox < d.interior_begin; ++ox)
    for (int ch = 0; ch < d.channels; ch += kLanes) pixel(d, ox, ch, lane_mask(d.channels - ch));
  for (; ox + kBlock <= d.interior_end; ox += kBlock)
    for (int ch = 0; ch < d.channels; ch += kLanes) block_fn(d, ox, ch, lane_mask(d.channels - ch));
  for (; ox < d.out_w; ++ox)
    for (int ch = 0; ch < d.channels; ch += kLanes) pixel(d, ox, ch, lane_mask(d.channels - ch));
}

}  // namespace

void depthwise_row(const DepthwiseRowArgs& d) {
  switch (d.kernel_w) {
    case 3: return row<3>(d);
    case 5: return row<5>(d);
    default: return row<0>(d);
  }
}

}  // namespace ampi::avx512
