// The dispatch table: one set of micro-kernel function pointers per instruction set,
// filled once at start-up (MNN-style). Op code (kernels/ops.h) calls through a table and
// never names an instruction set; tests and benchmarks walk every runnable table.
//
// Micro-kernels are pure functions: single-threaded, no allocation, no I/O. The op layer
// splits work across the thread pool and hands each call a range.
//
// Each ISA starts as a copy of the scalar reference table and overwrites the entries it
// accelerates, so a variant that does not pay for some op simply keeps the reference.
#pragma once
#include <cstdint>

#include "engine/isa.h"
#include "kernels/activation.h"

namespace ampi {

struct KernelTable {
  Isa isa = Isa::Scalar;

  // ---- element-wise ------------------------------------------------------------------
  // out[i] = act(a[i] + b[i]) for i in [0, n). out may alias a or b.
  void (*add)(const float* a, const float* b, int64_t n, ActivationSpec act, float* out) = nullptr;
  // x[i] = act(x[i]) for i in [0, n).
  void (*activate)(float* x, int64_t n, ActivationSpec act) = nullptr;
  // Gated convolution output: in is [pixels][2c] (feature channels, then gate channels);
  // out[p][j] = act(in[p][j]) * sigmoid(in[p][c + j]).
  void (*gated_output)(const float* in, int64_t pixels, int c, ActivationSpec act, float* out) = nullptr;

  // ---- channel layout and squeeze-excite -----------------------------------------------
  // out[p] = a[p] ++ b[p]: a is [pixels][ca], b is [pixels][cb], out [pixels][ca + cb].
  void (*concat_channels)(const float* a, int ca, const float* b, int cb, int64_t pixels,
                          float* out) = nullptr;
  // sum[j] = sum over p in [0, pixels) of in[p][j], added in pixel order.
  void (*channel_sum)(const float* in, int64_t pixels, int c, float* sum) = nullptr;
  // out[p][j] = in[p][j] * scale[j]; out may alias in.
  void (*channel_scale)(const float* in, int64_t pixels, int c, const float* scale, float* out) = nullptr;
  // Fully connected layer: y[r] = act(bias[r] + sum_j w[r][j] * x[j]), w is [rows][cols]
  // row-major; bias may be null.
  void (*dense)(const float* w, const float* bias, int rows, int cols, const float* x,
                ActivationSpec act, float* y) = nullptr;

  // ---- 2x resampling -----------------------------------------------------------------
  // Each computes rows [row_begin, row_end) of the half-resolution side, i.e. reads or
  // writes two full-resolution rows per row. h, w are the input's size, c its channels
  // before the DWT / after the IDWT. Formulas in kernels/ops.h.
  // Haar DWT: in [h][w][c] (h, w even) -> out [h/2][w/2][4c].
  void (*haar_dwt)(const float* in, int h, int w, int c, int row_begin, int row_end, float* out) = nullptr;
  // Inverse Haar DWT: in [h][w][4c] -> out [2h][2w][c].
  void (*haar_idwt)(const float* in, int h, int w, int c, int row_begin, int row_end, float* out) = nullptr;
  // in [h][w][c] -> out [2h][2w][c], nearest / bilinear (half-pixel centres).
  void (*resize2x_nearest)(const float* in, int h, int w, int c, int row_begin, int row_end,
                           float* out) = nullptr;
  void (*resize2x_bilinear)(const float* in, int h, int w, int c, int row_begin, int row_end,
                            float* out) = nullptr;
};

// The table for a variant; throws std::runtime_error if this build or CPU cannot run it.
const KernelTable& kernels_for(Isa isa);
// The table of active_isa() (AMPI_ISA or the best variant).
const KernelTable& kernels();

// Per-ISA fill functions, one per instruction set (kernels/*/register_*.cpp).
void fill_scalar_kernels(KernelTable& table);
void fill_avx2_kernels(KernelTable& table);
void fill_avx512_kernels(KernelTable& table);
void fill_neon_kernels(KernelTable& table);

}  // namespace ampi
