// AVX2 + FMA GEMM tile, 6 rows x 16 columns (two vectors): 12 accumulators, 2 weight
// vectors and one broadcast fill 15 of the 16 ymm registers, and 12 independent FMA
// chains cover the FMA latency (4 cycles) on two FMA ports. A panel whose last columns
// fit in one vector runs a 6x8 tile instead of multiplying zeros.
// Outputs larger than the last-level cache keep plain stores (GemmArgs::stream_c is
// ignored): streaming them as the AVX-512 tile does measured slower on this AMD EPYC (Zen 5) with
// 256-bit stores, 1x1 16->64 at 512x384 4.95 -> 5.17 ms (cpu clock, 1 thread, medians
// of alternating runs). Splitting the 6x8 tile's k over two accumulator sets (12 chains
// instead of 6) measured no better on 1x1 96->24 (2.53 -> 2.52 ms).
// As in the AVX-512 tile, the rows' pointers are set once per call and the activation
// kind is a template argument (with_fixed_activation, conv_epilogue.h): 96 x 1370 at
// k = 64 on 1 thread 128 -> 134 GFLOP/s.
#include <algorithm>

#include "kernels/conv_epilogue.h"
#include "kernels/x86/avx2_kernels.h"
#include "kernels/x86/avx2_math.h"

namespace ampi::avx2 {
namespace {

// Lanes [0, count) set.
__m256i lane_mask(int count) {
  return _mm256_cmpgt_epi32(_mm256_set1_epi32(count), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
}

// Stores v (+ residual) into `columns` floats of c
// (columns >= 1; only the first 8 are written).
inline void store_columns(__m256 v, float* c, const float* residual, int columns) {
  if (columns >= 8) {
    if (residual) v = _mm256_add_ps(v, _mm256_loadu_ps(residual));
    _mm256_storeu_ps(c, v);
  } else {
    const __m256i m = lane_mask(columns);
    if (residual) v = _mm256_add_ps(v, _mm256_maskload_ps(residual, m));
    _mm256_maskstore_ps(c, m, v);
  }
}

// Rows [0, m) x columns [j0, j0 + columns) of the output from one packed panel (a holds
// the tile's row pointers); columns <= 8 * kVectors. kAct: the activation kind
// (conv_epilogue.h).
template <int kVectors, int kAct>
void panel_tile(const GemmArgs& g, const float* const (&a)[kGemmMr], const float* panel, int j0, int columns) {
  const int m = g.m, k = g.k;
  __m256 acc[kGemmMr][kVectors];
  for (int v = 0; v < kVectors; ++v) {
    const __m256 bias = _mm256_loadu_ps(panel + 8 * v);
    for (int r = 0; r < kGemmMr; ++r) acc[r][v] = bias;
  }
  const float* b = panel + kGemmNr;
  for (int kk = 0; kk < k; ++kk, b += kGemmNr) {
    __m256 bv[kVectors];
    for (int v = 0; v < kVectors; ++v) bv[v] = _mm256_loadu_ps(b + 8 * v);
    for (int r = 0; r < kGemmMr; ++r) {
      const __m256 av = _mm256_broadcast_ss(a[r] + kk);
      for (int v = 0; v < kVectors; ++v) acc[r][v] = _mm256_fmadd_ps(av, bv[v], acc[r][v]);
    }
  }
  // Unrolled, so every acc index is a constant, and each row copied out before the
  // activation takes it by reference: the accumulators then live in registers only (a
  // runtime row loop, or activating acc[r] itself, makes GCC mirror all 12 to the stack
  // on every k step, 12 stores beside the 12 FMAs).
#pragma GCC unroll 16
  for (int r = 0; r < kGemmMr; ++r) {
    if (r >= m) continue;
    __m256 out[kVectors];
    for (int v = 0; v < kVectors; ++v) out[v] = acc[r][v];
    activate_tile_of<kAct>(out, g.act, [](__m256 x, ActivationSpec a) { return activate(x, a); });
    float* c = g.c + r * g.c_stride + j0;
    const float* res = g.residual ? g.residual + r * g.c_stride + j0 : nullptr;
    for (int v = 0; v < kVectors; ++v)
      store_columns(out[v], c + 8 * v, res ? res + 8 * v : nullptr, columns - 8 * v);
  }
}

template <int kAct>
void panels(const GemmArgs& g) {
  const int64_t panel_floats = static_cast<int64_t>(1 + g.k) * kGemmNr;
  // Rows past m re-read row m-1 (their results are dropped): no branches in the k loop.
  const float* a[kGemmMr];
  for (int r = 0; r < kGemmMr; ++r) a[r] = g.a + std::min(r, g.m - 1) * g.a_stride;
  const float* panel = g.packed;
  for (int j0 = 0; j0 < g.n; j0 += kGemmNr, panel += panel_floats) {
    const int columns = std::min(kGemmNr, g.n - j0);
    if (columns > 8)
      panel_tile<2, kAct>(g, a, panel, j0, columns);
    else
      panel_tile<1, kAct>(g, a, panel, j0, columns);
  }
}

}  // namespace

void gemm(const GemmArgs& g) {
  // Into L2 (prefetcht1): the tile reads it only in the next call.
  for (int64_t i = 0; i < g.prefetch_floats; i += 16) __builtin_prefetch(g.prefetch_a + i, 0, 2);
  with_fixed_activation(kGemmActivations, g.act.kind, [&](auto act) { panels<decltype(act)::value>(g); });
}

}  // namespace ampi::avx2
