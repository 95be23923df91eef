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

// ---- convolution micro-kernel arguments (used by the "convolution" entries below) ------
// One GEMM tile: C[i][j] = act(bias[j] + sum_kk A[i][kk] * B[kk][j]) (+ R[i][j]) for
// i < m, j < n. B and bias come packed (kernels/conv.h, pack_gemm_weights): ceil(n / nr)
// panels of nr columns, each [bias: nr][k][nr], zero padded past n.
struct GemmArgs {
  int m = 0, n = 0, k = 0;          // rows (1..gemm_mr), output columns, reduction length
  const float* a = nullptr;         // m rows of k floats, a_stride floats apart
  int64_t a_stride = 0;
  const float* packed = nullptr;    // packed bias and B for this table's gemm_nr
  float* c = nullptr;               // m rows of n floats, c_stride floats apart
  int64_t c_stride = 0;
  // nullptr, or laid out like c (same stride); may be c itself, to accumulate into it:
  // every kernel reads a residual value before it writes that element of c.
  const float* residual = nullptr;
  ActivationSpec act;
  // The whole output is larger than the last-level cache (it is evicted before the next
  // layer reads it back), c and c_stride are 64-byte aligned and n a multiple of 16:
  // kernels may store whole lines with non-temporal stores, which skip reading each
  // output line from memory before writing it.
  bool stream_c = false;
  // The next call's A, floats [prefetch_a, prefetch_a + prefetch_floats) (nullptr: none):
  // kernels may prefetch it while this tile computes, so the next call does not wait for
  // memory.
  const float* prefetch_a = nullptr;
  int64_t prefetch_floats = 0;
};

// The tallest depthwise kernel the row kernels take (in_rows has kernel_h entries).
constexpr int kMaxDepthwiseKernelH = 16;

// One output row of a depthwise convolution (channel multiplier 1), NHWC:
// out[x][c] = act(bias[c] + sum_{ky,kx} w[ky][kx][c] * row_ky[x*stride_w - pad_left +
// kx*dilation_w][c]) (+ residual[x][c]); taps outside the row or on a padding row count 0.
struct DepthwiseRowArgs {
  const float* const* in_rows = nullptr;  // kernel_h input rows; nullptr: a padding row
  int in_w = 0, channels = 0;
  int kernel_h = 0, kernel_w = 0, stride_w = 1, dilation_w = 1, pad_left = 0;
  int out_w = 0;
  // Output columns [interior_begin, interior_end) have all kernel_w taps inside the row,
  // so kernels may skip the bounds checks there.
  int interior_begin = 0, interior_end = 0;
  const float* weights = nullptr;   // [kernel_h][kernel_w][channels]
  const float* bias = nullptr;      // [channels]
  float* out = nullptr;             // [out_w][channels]
  const float* residual = nullptr;  // nullptr or [out_w][channels]
  ActivationSpec act;
  // The input row the next output row reads first and this one does not (nullptr if
  // none): kernels may prefetch it at the columns they are reading, so the next call
  // finds it in cache instead of waiting for memory.
  const float* prefetch_row = nullptr;
  // The output is larger than the last-level cache (it is evicted before the
  // next layer reads it back), out is 64-byte aligned and channels a multiple of 16:
  // kernels may store whole lines with non-temporal stores, which skip reading each
  // output line from memory before writing it (a third of a depthwise layer's traffic).
  bool stream_out = false;
};

struct KernelTable {
  Isa isa = Isa::Scalar;

  // ---- convolution -------------------------------------------------------------------
  // The register tile of gemm: rows of A per call (m <= gemm_mr), columns per packed panel.
  int gemm_mr = 0, gemm_nr = 0;
  void (*gemm)(const GemmArgs& args) = nullptr;
  void (*depthwise_row)(const DepthwiseRowArgs& args) = nullptr;

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
