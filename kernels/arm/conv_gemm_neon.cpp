// NEON GEMM tile, 8 rows x 8 columns (two vectors): 16 accumulators. The k loop goes four
// steps at a time: one 4-float load per row of A, then lane-indexed FMAs (vfmaq_laneq),
// so 8 A vectors + 2 weight vectors + 16 accumulators fit in the 32 q registers. A panel
// whose last columns fit in one vector runs an 8x4 tile.
#include <algorithm>

#include "kernels/arm/neon_kernels.h"
#include "kernels/arm/neon_math.h"
#include "kernels/conv_epilogue.h"

namespace ampi::neon {
namespace {

// Stores v (+ residual) into `columns` floats of c.
inline void store_columns(float32x4_t v, float* c, const float* residual, int columns) {
  if (columns >= 4) {
    vst1q_f32(c, residual ? vaddq_f32(v, vld1q_f32(residual)) : v);
    return;
  }
  float lanes[4];
  vst1q_f32(lanes, v);
  for (int j = 0; j < columns; ++j) c[j] = lanes[j] + (residual ? residual[j] : 0.0f);
}

// One k step: acc[r] += B[kk] * A[r][kk], A[r][kk] being lane kLane of av[r].
template <int kLane, int kVectors>
inline void k_step(float32x4_t (&acc)[kGemmMr][kVectors], const float32x4_t (&av)[kGemmMr], const float* b) {
  float32x4_t bv[kVectors];
  for (int v = 0; v < kVectors; ++v) bv[v] = vld1q_f32(b + 4 * v);
  for (int r = 0; r < kGemmMr; ++r)
    for (int v = 0; v < kVectors; ++v) acc[r][v] = vfmaq_laneq_f32(acc[r][v], bv[v], av[r], kLane);
}

// Rows [0, m) x columns [j0, j0 + columns) of the output from one packed panel;
// columns <= 4 * kVectors.
template <int kVectors>
void panel_tile(const GemmArgs& g, const float* panel, int j0, int columns) {
  const int m = g.m, k = g.k;
  // Rows past m re-read row m-1 (their results are dropped): no branches in the k loop.
  const float* a[kGemmMr];
  for (int r = 0; r < kGemmMr; ++r) a[r] = g.a + std::min(r, m - 1) * g.a_stride;
  float32x4_t acc[kGemmMr][kVectors];
  for (int v = 0; v < kVectors; ++v) {
    const float32x4_t bias = vld1q_f32(panel + 4 * v);
    for (int r = 0; r < kGemmMr; ++r) acc[r][v] = bias;
  }
  const float* b = panel + kGemmNr;
  float32x4_t av[kGemmMr];
  int kk = 0;
  for (; kk + 4 <= k; kk += 4, b += 4 * kGemmNr) {
    for (int r = 0; r < kGemmMr; ++r) av[r] = vld1q_f32(a[r] + kk);
    k_step<0>(acc, av, b);
    k_step<1>(acc, av, b + kGemmNr);
    k_step<2>(acc, av, b + 2 * kGemmNr);
    k_step<3>(acc, av, b + 3 * kGemmNr);
  }
  for (; kk < k; ++kk, b += kGemmNr) {
    for (int r = 0; r < kGemmMr; ++r) av[r] = vld1q_dup_f32(a[r] + kk);
    k_step<0>(acc, av, b);
  }
  // Unrolled, so every acc index is a constant and the accumulators live in registers
  // only (a runtime row loop here makes GCC mirror them to the stack in the k loop).
#pragma GCC unroll 16
  for (int r = 0; r < kGemmMr; ++r) {
    if (r >= m) continue;
    activate_tile(acc[r], g.act, [](float32x4_t x, ActivationSpec a) { return activate(x, a); });
    float* c = g.c + r * g.c_stride + j0;
    const float* res = g.residual ? g.residual + r * g.c_stride + j0 : nullptr;
    for (int v = 0; v < kVectors; ++v)
      store_columns(acc[r][v], c + 4 * v, res ? res + 4 * v : nullptr, columns - 4 * v);
  }
}

}  // namespace

void gemm(const GemmArgs& g) {
  const int64_t panel_floats = static_cast<int64_t>(1 + g.k) * kGemmNr;
  const float* panel = g.packed;
  for (int j0 = 0; j0 < g.n; j0 += kGemmNr, panel += panel_floats) {
    const int columns = std::min(kGemmNr, g.n - j0);
    if (columns > 4)
      panel_tile<2>(g, panel, j0, columns);
    else
      panel_tile<1>(g, panel, j0, columns);
  }
}

}  // namespace ampi::neon
