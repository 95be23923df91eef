// The plain scalar reference of every micro-kernel: the definition each SIMD variant is
// tested against, and the fallback where no variant pays.
#pragma once
#include <cstdint>

#include "kernels/activation.h"
#include "kernels/kernel_table.h"

namespace ampi::reference {

void add(const float* a, const float* b, int64_t n, ActivationSpec act, float* out);
void activate(float* x, int64_t n, ActivationSpec act);

// ---- channel operations (channels.cpp); see kernels/kernel_table.h for the contracts ----
void gated_output(const float* in, int64_t pixels, int c, ActivationSpec act, float* out);
void concat_channels(const float* a, int ca, const float* b, int cb, int64_t pixels, float* out);
void channel_sum(const float* in, int64_t pixels, int c, float* sum);
void channel_scale(const float* in, int64_t pixels, int c, const float* scale, float* out);
void dense(const float* w, const float* bias, int rows, int cols, const float* x,
           ActivationSpec act, float* y);

// ---- 2x resampling (resample.cpp) ----------------------------------------------------
void haar_dwt(const float* in, int h, int w, int c, int row_begin, int row_end, float* out);
void haar_idwt(const float* in, int h, int w, int c, int row_begin, int row_end, float* out);
void resize2x_nearest(const float* in, int h, int w, int c, int row_begin, int row_end, float* out);
void resize2x_bilinear(const float* in, int h, int w, int c, int row_begin, int row_end, float* out);

// ---- convolution (conv_gemm.cpp, conv_depthwise.cpp); contracts in kernel_table.h -----
// A 4x8 GEMM tile (written plainly; the compiler may auto-vectorise it) and one depthwise
// row. The naive direct convolution the tests compare with is in conv_reference.h.
constexpr int kGemmMr = 4, kGemmNr = 8;
void gemm(const GemmArgs& args);
void depthwise_row(const DepthwiseRowArgs& args);

}  // namespace ampi::reference
