// AVX-512 GEMM tile, 12 rows x 32 columns (two vectors): 24 accumulators, 2 weight
// vectors and one broadcast in the 32 zmm registers; the broadcast folds into the FMA's
// memory operand. A panel whose last columns fit in 24, 16 or 8 lanes runs a 12x24,
// 12x16 or 12x8 tile.
// Column tails use masked loads and stores, so no lane outside the output is touched.
// Outputs larger than the last-level cache go out with streaming stores (stream_c):
// 1x1 16->64 at 512x384 (12 MB in, 50 MB out): 4.8 -> 3.2 ms on 1 thread, 2.4 -> 1.6 ms
// on 2. The next tile's A rows are prefetched while this one computes (GemmArgs::
// prefetch_a), medians on 1 thread: 1x1 64->16 at 512x384 (50 MB in) 5.1 -> 3.1 ms,
// 64->64 at 256x192 2.9 -> 2.3 ms, 128->128 at 128x96 2.2 -> 1.9 ms.
// The rows' pointers are set once per call, and the activation kind is a template
// argument for the kinds the networks use (with_fixed_activation, conv_epilogue.h): a
// switch per row in the epilogue made GCC spill accumulators. Short reductions gain most:
// 96 x 1370 on 1 thread (attention's Q K^T shape, no activation) 243 -> 256 GFLOP/s at
// k = 64, 214 -> 241 at k = 32; ViT-S's fc1 with GELU 7.1-7.4 -> 6.7-6.8 ms.
#include <algorithm>

#include "kernels/conv_epilogue.h"
#include "kernels/x86/avx512_kernels.h"
#include "kernels/x86/avx512_math.h"

namespace ampi::avx512 {
namespace {

// Lanes [0, count) set; count >= 16 sets all.
inline __mmask16 lane_mask(int count) {
  return count >= 16 ? static_cast<__mmask16>(0xffff) : static_cast<__mmask16>((1u << count) - 1u);
}

// Stores v (+ residual) into `columns` floats of c.
inline void store_columns(__m512 v, float* c, const float* residual, int columns) {
  const __mmask16 m = lane_mask(columns);
  if (residual) v = _mm512_add_ps(v, _mm512_maskz_loadu_ps(m, residual));
  _mm512_mask_storeu_ps(c, m, v);
}

// Streams v (+ residual) into 16 floats of c, a whole 64-byte-aligned line
// (GemmArgs::stream_c).
inline void stream_columns(__m512 v, float* c, const float* residual) {
  if (residual) v = _mm512_add_ps(v, _mm512_loadu_ps(residual));
  _mm512_stream_ps(c, v);
}

// Rows [0, m) x columns [j0, j0 + columns) of the output from one packed panel (a holds
// the tile's row pointers): kFull 16-lane vectors, then (kHalf) one 8-lane vector for a
// panel whose last columns fit in 8. The half vector is a 256-bit FMA, which on cores
// that split 512-bit FMAs in two (AMD Zen 4) costs half a full one, and on others no
// more. columns <= 16 * kFull + 8 * kHalf, == 16 * kFull when kStream. kAct: the
// activation kind (conv_epilogue.h).
template <int kFull, bool kHalf, bool kStream, int kAct>
void panel_tile(const GemmArgs& g, const float* const (&a)[kGemmMr], const float* panel, int j0, int columns) {
  static_assert(!(kHalf && kStream), "streamed outputs are whole 16-lane lines");
  constexpr int kVectors = kFull + (kHalf ? 1 : 0);
  const int m = g.m, k = g.k;
  __m512 acc[kGemmMr][kFull > 0 ? kFull : 1];
  __m256 half[kGemmMr];
  for (int v = 0; v < kFull; ++v) {
    const __m512 bias = _mm512_loadu_ps(panel + 16 * v);
    for (int r = 0; r < kGemmMr; ++r) acc[r][v] = bias;
  }
  if constexpr (kHalf) {
    const __m256 bias = _mm256_loadu_ps(panel + 16 * kFull);
    for (int r = 0; r < kGemmMr; ++r) half[r] = bias;
  }
  const float* b = panel + kGemmNr;
  for (int kk = 0; kk < k; ++kk, b += kGemmNr) {
    __m512 bv[kFull > 0 ? kFull : 1];
    for (int v = 0; v < kFull; ++v) bv[v] = _mm512_loadu_ps(b + 16 * v);
    __m256 bh = kHalf ? _mm256_loadu_ps(b + 16 * kFull) : _mm256_setzero_ps();
    for (int r = 0; r < kGemmMr; ++r) {
      const __m512 av = _mm512_set1_ps(a[r][kk]);
      for (int v = 0; v < kFull; ++v) acc[r][v] = _mm512_fmadd_ps(av, bv[v], acc[r][v]);
      if constexpr (kHalf) half[r] = _mm256_fmadd_ps(_mm512_castps512_ps256(av), bh, half[r]);
    }
  }
  // Unrolled, so every acc index is a constant and the accumulators live in registers
  // only (a runtime row loop here makes GCC mirror them to the stack in the k loop).
#pragma GCC unroll 16
  for (int r = 0; r < kGemmMr; ++r) {
    if (r >= m) continue;
    __m512 out[kVectors];
    for (int v = 0; v < kFull; ++v) out[v] = acc[r][v];
    if constexpr (kHalf) out[kFull] = _mm512_zextps256_ps512(half[r]);
    activate_tile_of<kAct>(out, g.act, [](__m512 x, ActivationSpec a) { return activate(x, a); });
    float* c = g.c + r * g.c_stride + j0;
    const float* res = g.residual ? g.residual + r * g.c_stride + j0 : nullptr;
    for (int v = 0; v < kVectors; ++v) {
      if constexpr (kStream)
        stream_columns(out[v], c + 16 * v, res ? res + 16 * v : nullptr);
      else
        store_columns(out[v], c + 16 * v, res ? res + 16 * v : nullptr, columns - 16 * v);
    }
  }
}

template <bool kStream, int kAct>
void panels(const GemmArgs& g) {
  const int64_t panel_floats = static_cast<int64_t>(1 + g.k) * kGemmNr;
  // Rows past m re-read row m-1 (their results are dropped): no branches in the k loop.
  const float* a[kGemmMr];
  for (int r = 0; r < kGemmMr; ++r) a[r] = g.a + std::min(r, g.m - 1) * g.a_stride;
  const float* panel = g.packed;
  for (int j0 = 0; j0 < g.n; j0 += kGemmNr, panel += panel_floats) {
    const int columns = std::min(kGemmNr, g.n - j0);
    if (columns > 24)
      panel_tile<2, false, kStream, kAct>(g, a, panel, j0, columns);
    else if constexpr (kStream)  // whole lines: 16 columns
      panel_tile<1, false, true, kAct>(g, a, panel, j0, columns);
    else if (columns > 16)
      panel_tile<1, true, false, kAct>(g, a, panel, j0, columns);
    else if (columns > 8)
      panel_tile<1, false, false, kAct>(g, a, panel, j0, columns);
    else
      panel_tile<0, true, false, kAct>(g, a, panel, j0, columns);
  }
}

template <bool kStream>
void panels(const GemmArgs& g) {
  with_fixed_activation(kGemmActivations, g.act.kind, [&](auto act) { panels<kStream, decltype(act)::value>(g); });
}

}  // namespace

void gemm(const GemmArgs& g) {
  // Into L2 (prefetcht1): the tile reads it only in the next call.
  for (int64_t i = 0; i < g.prefetch_floats; i += 16) __builtin_prefetch(g.prefetch_a + i, 0, 2);
  if (!g.stream_c) return panels<false>(g);
  panels<true>(g);
  _mm_sfence();  // the streamed lines before the stores that follow (the pool's "done")
}

}  // namespace ampi::avx512
