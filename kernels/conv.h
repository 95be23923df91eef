// 2-D convolution, the op the depth and inpainting networks spend their time in.
//
// Layouts: input NHWC [in_h][in_w][in_c], output [out_h][out_w][out_c], weights OHWI
// [out_c][kernel_h][kernel_w][in_c / groups] (PyTorch's OIHW transposed), bias [out_c].
// The epilogue is fused: out = act(conv(in) + bias) + residual.
//
// Conv2d packs its weights once, for one dispatch table, and picks one of six paths by
// shape (the choice is fixed at construction):
//   pointwise  1x1, stride 1, no padding, groups 1: the input already is the GEMM's A
//              matrix (pixels x in_c); the GEMM op (kernels/gemm.h) runs on it directly
//              with the packed filters.
//   depthwise  groups == in_c == out_c: the table's depthwise_row kernel, one output row
//              per call, vectorised across channels.
//   taps       a k x k convolution with at most 4 outputs, stride 1, groups 1 (a head
//              that predicts a few channels): im2col's gemm would fill a quarter of an
//              AVX-512 tile's lanes or less. Instead one gemm over each input row gives
//              every tap's contribution (kernel_h*kernel_w*out_c columns), and each output
//              pixel adds its taps' contributions from the rows and columns they read.
//   winograd   a 3x3 convolution, stride 1, no dilation, one group, at least 8 inputs
//              and more than 4 outputs: Winograd's F(4x4, 3x3) (kernels/winograd.h), a
//              quarter of the multiply-adds. Per chunk of 4x4 output tiles (in row-major
//              order, sized to stay in L2): the table's winograd_input transforms each
//              tile's 6x6 window, 36 GEMMs [tiles x in_c] x [in_c x out_c] run on the
//              micro-kernel (the filters transformed and packed once), winograd_output
//              makes the outputs with the epilogue. It rounds differently from a direct
//              sum, within the same 1e-5 of the output's scale the tests hold every path
//              to.
//   rows       any other convolution with one group (implicit GEMM): for an output row,
//              the gemm's A rows are read straight from the input rows, a_stride
//              stride_w*in_c apart; one call per kernel row adds a run of kernel_w*in_c
//              contiguous inputs (one call per tap when dilated across the row) into the
//              output tile. Rows with horizontal padding are copied between zero columns
//              once, not once per tap as im2col does.
//   general    anything else (grouped, or runs under 16 floats): per pixel tile and group,
//              im2col into a per-thread scratch buffer, then the same gemm tile.
// Threads split the output pixels (pointwise, general), output rows (depthwise, taps,
// rows) or chunks of tile rows (winograd); every output value is computed by the same
// code in the same order whatever the thread count, so results are bitwise identical
// across thread counts.
#pragma once
#include <cstdint>
#include <memory>

#include "engine/thread_pool.h"
#include "kernels/gemm.h"
#include "kernels/kernel_table.h"

namespace ampi {

struct ConvParams {
  int in_c = 0, out_c = 0;
  int kernel_h = 1, kernel_w = 1;
  int stride_h = 1, stride_w = 1;
  int pad_top = 0, pad_left = 0, pad_bottom = 0, pad_right = 0;
  int dilation_h = 1, dilation_w = 1;
  int groups = 1;
  ActivationSpec act;

  // (in_h + pad_top + pad_bottom - dilation_h*(kernel_h-1) - 1)/stride_h + 1; zero or
  // less when the dilated kernel does not fit.
  int out_h(int in_h) const;
  int out_w(int in_w) const;
};

// Throws std::runtime_error naming the first invalid field ("conv: groups 3 does not
// divide in_c 16").
void validate(const ConvParams& p);

class Conv2d {
 public:
  enum class Path { Pointwise, Depthwise, Taps, Winograd, Rows, General };

  Conv2d() = default;
  // weights OHWI [out_c][kernel_h][kernel_w][in_c/groups]; bias [out_c] or nullptr.
  // Packs the weights once, for the table's ISA. Validates the params (throws).
  Conv2d(const ConvParams& p, const float* weights, const float* bias,
         const KernelTable& k = kernels());

  const ConvParams& params() const { return p_; }
  Path path() const { return path_; }
  // For ops that call the micro-kernels themselves (kernels/inverted_residual.h): the
  // table the weights were packed for, and the arguments of its kernels for this layer.
  const KernelTable& table() const { return *k_; }
  // Depthwise: a row of out_w outputs from input rows of in_w pixels, output column 0
  // reading input column -pad_left; in_rows, out and residual are the caller's to set.
  DepthwiseRowArgs depthwise_row_args(int in_w, int out_w, int pad_left) const;
  // Pointwise: everything but the rows (m, a, c, residual).
  GemmArgs pointwise_gemm_args() const;

  // in: NHWC [in_h][in_w][in_c]; out: [out_h][out_w][out_c];
  // out = act(conv(in) + bias) + residual   (residual: nullptr or the shape of out)
  // in and out never alias. Uses the pool for threading. Throws std::runtime_error on an
  // empty Conv2d or an input too small for the dilated kernel.
  void run(const float* in, int in_h, int in_w, float* out, const float* residual = nullptr,
           ThreadPool& pool = default_pool()) const;
  // A pointwise convolution of the input with input channel j multiplied by in_scale[j]
  // (a squeeze-excite gate, SqueezeExcite::gate): the scale goes into a copy of the packed
  // weights, so the input is read once, as it is. Throws std::runtime_error on other paths.
  void run_scaled_input(const float* in, int in_h, int in_w, const float* in_scale, float* out,
                        const float* residual = nullptr, ThreadPool& pool = default_pool()) const;

 private:
  // Throws std::runtime_error naming `method` on an empty Conv2d, or on an input that is
  // empty or too small for the dilated kernel.
  void check_input(const char* method, int in_h, int in_w) const;
  void run_pointwise(const float* packed, const float* in, int64_t pixels, float* out,
                     const float* residual, ThreadPool& pool) const;
  void run_depthwise(const float* in, int in_h, int in_w, float* out, const float* residual,
                     ThreadPool& pool) const;
  void run_taps(const float* in, int in_h, int in_w, float* out, const float* residual,
                ThreadPool& pool) const;
  void run_winograd(const float* in, int in_h, int in_w, float* out, const float* residual,
                    ThreadPool& pool) const;
  void run_rows(const float* in, int in_h, int in_w, float* out, const float* residual,
                ThreadPool& pool) const;
  void run_general(const float* in, int in_h, int in_w, float* out, const float* residual,
                   ThreadPool& pool) const;

  ConvParams p_;
  Path path_ = Path::General;
  const KernelTable* k_ = nullptr;
  // Packed weights, immutable after construction (shared by copies of this Conv2d).
  // Pointwise/general: one pack_gemm_weights block per group, group_stride_ floats apart.
  // Depthwise: [kernel_h][kernel_w][channels] weights, then [channels] bias.
  // Rows: one pack_gemm_weights block without bias per run (kernel row, then run within
  // the row), group_stride_ floats apart, then [out_c] bias.
  // Taps: one pack_gemm_weights block without bias (column tap * out_c + j holds output
  // j's weights of one tap), group_stride_ floats, then [out_c] bias.
  // Winograd: one pack_gemm_weights block without bias per transform position (the
  // filters' U = G g G^T at that position), group_stride_ floats apart, then [out_c] bias.
  std::shared_ptr<const float> packed_;
  int64_t group_stride_ = 0;
};

}  // namespace ampi
