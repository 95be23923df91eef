// NEON GEMM tile, 8 rows x 8 columns (two vectors): 16 accumulators. The k loop goes four
// steps at a time: one 4-float load per row of A, then lane-indexed FMAs (vfmaq_laneq),
// so 8 A vectors + 2 weight vectors + 16 accumulators fit in the 32 q registers. A panel
// whose last columns are fewer than 8 runs the same tile: packing zero-fills the panel's
// columns past n, and the stores drop them.
//
// The accumulators are 16 named variables, not an array: with acc[8][2] GCC 12 kept a
// copy of the array in memory, 8 stores of q-register pairs in every pass of the k loop
// (44 cycles per pass where the FMAs alone need 32, in bench/arm_model.py's Neoverse-N1
// model); named, the loop is loads and FMAs only (33 cycles).
#include <algorithm>

#include "kernels/arm/neon_kernels.h"
#include "kernels/arm/neon_math.h"
#include "kernels/conv_epilogue.h"

namespace ampi::neon {
namespace {

static_assert(kGemmMr == 8 && kGemmNr == 8, "the tile below is written out for 8 x 8");

// Stores v (+ residual) into `columns` floats of c (nothing when columns <= 0).
inline void store_columns(float32x4_t v, float* c, const float* residual, int columns) {
  if (columns >= 4) {
    vst1q_f32(c, residual ? vaddq_f32(v, vld1q_f32(residual)) : v);
    return;
  }
  float lanes[4];
  vst1q_f32(lanes, v);
  for (int j = 0; j < columns; ++j) c[j] = lanes[j] + (residual ? residual[j] : 0.0f);
}

// X(r) for each row of the tile.
#define AMPI_TILE_ROWS(X) X(0) X(1) X(2) X(3) X(4) X(5) X(6) X(7)
// Row r's two accumulators += the k step's two weight vectors times lane L of row r's A.
#define AMPI_ROW_FMA(r, L)                              \
  c##r##_0 = vfmaq_laneq_f32(c##r##_0, b0, a##r, L); \
  c##r##_1 = vfmaq_laneq_f32(c##r##_1, b1, a##r, L);
// One k step: the panel's 8 weights at `w`, lane L of every row's A vector.
#define AMPI_K_STEP(w, L)                                                                          \
  {                                                                                                \
    const float32x4_t b0 = vld1q_f32(w), b1 = vld1q_f32((w) + 4);                                  \
    AMPI_ROW_FMA(0, L) AMPI_ROW_FMA(1, L) AMPI_ROW_FMA(2, L) AMPI_ROW_FMA(3, L) AMPI_ROW_FMA(4, L) \
    AMPI_ROW_FMA(5, L) AMPI_ROW_FMA(6, L) AMPI_ROW_FMA(7, L)                                       \
  }

// Rows [0, m) x columns [j0, j0 + columns) of the output from one packed panel. kAct:
// the activation kind, fixed at compile time as on x86 (conv_epilogue.h).
template <int kAct>
void panel_tile(const GemmArgs& g, const float* panel, int j0, int columns) {
  const int m = g.m, k = g.k;
  // Rows past m re-read row m-1 (their results are dropped): no branches in the k loop.
#define AMPI_ROW_POINTER(r) const float* row##r = g.a + std::min(r, m - 1) * g.a_stride;
  AMPI_TILE_ROWS(AMPI_ROW_POINTER)
  const float32x4_t bias0 = vld1q_f32(panel), bias1 = vld1q_f32(panel + 4);
#define AMPI_ACCUMULATORS(r) float32x4_t c##r##_0 = bias0, c##r##_1 = bias1;
  AMPI_TILE_ROWS(AMPI_ACCUMULATORS)

  const float* b = panel + kGemmNr;
  int kk = 0;
  for (; kk + 4 <= k; kk += 4, b += 4 * kGemmNr) {
#define AMPI_LOAD_A4(r) const float32x4_t a##r = vld1q_f32(row##r + kk);
    AMPI_TILE_ROWS(AMPI_LOAD_A4)
    AMPI_K_STEP(b, 0)
    AMPI_K_STEP(b + kGemmNr, 1)
    AMPI_K_STEP(b + 2 * kGemmNr, 2)
    AMPI_K_STEP(b + 3 * kGemmNr, 3)
  }
  for (; kk < k; ++kk, b += kGemmNr) {
#define AMPI_LOAD_A1(r) const float32x4_t a##r = vld1q_dup_f32(row##r + kk);
    AMPI_TILE_ROWS(AMPI_LOAD_A1)
    AMPI_K_STEP(b, 0)
  }

  float32x4_t tile[kGemmMr][2] = {{c0_0, c0_1}, {c1_0, c1_1}, {c2_0, c2_1}, {c3_0, c3_1},
                                  {c4_0, c4_1}, {c5_0, c5_1}, {c6_0, c6_1}, {c7_0, c7_1}};
  for (int r = 0; r < std::min(m, kGemmMr); ++r) {
    activate_tile_of<kAct>(tile[r], g.act, [](float32x4_t x, ActivationSpec a) { return activate(x, a); });
    float* c = g.c + r * g.c_stride + j0;
    const float* res = g.residual ? g.residual + r * g.c_stride + j0 : nullptr;
    for (int v = 0; v < 2; ++v) store_columns(tile[r][v], c + 4 * v, res ? res + 4 * v : nullptr, columns - 4 * v);
  }
}

#undef AMPI_TILE_ROWS
#undef AMPI_ROW_FMA
#undef AMPI_K_STEP
#undef AMPI_ROW_POINTER
#undef AMPI_ACCUMULATORS
#undef AMPI_LOAD_A4
#undef AMPI_LOAD_A1

}  // namespace

void gemm(const GemmArgs& g) {
  const int64_t panel_floats = static_cast<int64_t>(1 + g.k) * kGemmNr;
  with_fixed_activation(kGemmActivations, g.act.kind, [&](auto act) {
    const float* panel = g.packed;
    for (int j0 = 0; j0 < g.n; j0 += kGemmNr, panel += panel_floats)
      panel_tile<decltype(act)::value>(g, panel, j0, std::min(kGemmNr, g.n - j0));
  });
}

}  // namespace ampi::neon
