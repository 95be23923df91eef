// The dispatch table: one set of micro-kernel function pointers per instruction set,
// filled once at start-up (MNN-style). Op code (kernels/ops.h) calls through a table and
// never names an instruction set; tests and benchmarks walk every runnable table.
//
// The families, their signatures and which instruction sets have a variant of each come
// from one list, kernels/kernel_list.def; the table's fields, every ISA's declarations
// and the registration (kernels/kernel_table.cpp) are generated from it. Each ISA's
// table starts from the scalar reference and takes the variants the list claims for it,
// so a variant that does not pay for some op simply keeps the reference.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/isa.h"
#include "kernels/activation.h"
#include "kernels/kernel_lists.h"

namespace ampi {

// ---- arguments of the gemm and depthwise_row kernels ----------------------------------
// One GEMM tile: C[i][j] = act(bias[j] + sum_kk A[i][kk] * B[kk][j]) (+ R[i][j]) for
// i < m, j < n. B and bias come packed (kernels/gemm.h, pack_gemm_panels): ceil(n / nr)
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

// One tile of a Winograd F(4x4, 3x3) convolution's output (kernels/winograd.h): the
// 4x4 outputs Y = A^T M A of the 36 products M, plus bias, activation and residual.
struct WinogradOutputArgs {
  const float* m = nullptr;  // position xi's channels at m + xi * m_stride
  int64_t m_stride = 0;
  int channels = 0;
  const float* bias = nullptr;      // [channels]
  ActivationSpec act;
  float* out = nullptr;             // output (y, x) at out + y * row_stride + x * channels
  int64_t row_stride = 0;
  const float* residual = nullptr;  // nullptr, or laid out like out
  // The outputs inside the map: rows [0, rows) and columns [0, cols) of the tile, 1..4
  // each; the others are not written.
  int rows = 4, cols = 4;
};

// Which instruction set's code each entry of a table runs: the table's own variant, or
// the one it falls back to (kernels/kernel_list.def says which ISA has which).
struct KernelProviders {
#define AMPI_KERNEL(name, ...) Isa name = Isa::Scalar;
#include "kernels/kernel_list.def"
};

// One entry per family of kernels/kernel_list.def, in its order; the contracts are there.
struct KernelTable {
  Isa isa = Isa::Scalar;
  // The register tile of gemm: rows of A per call (m <= gemm_mr), columns per packed
  // panel. It belongs to the gemm kernel: the tile of whichever ISA provides it.
  int gemm_mr = 0, gemm_nr = 0;
#define AMPI_KERNEL(name, return_type, parameters, ...) return_type(*name) parameters = nullptr;
#include "kernels/kernel_list.def"
  KernelProviders provided_by;
};

// The table for a variant; throws std::runtime_error if this build or CPU cannot run it.
const KernelTable& kernels_for(Isa isa);
// The table of active_isa() (AMPI_ISA or the best variant).
const KernelTable& kernels();

// Every family of kernels/kernel_list.def, in its order.
const std::vector<KernelFamily>& kernel_families();
// What `table` runs for each family, in the list's order.
std::vector<KernelEntry> kernel_entries(const KernelTable& table);

}  // namespace ampi
