// NEON micro-kernels (4 floats per vector), AArch64 only.
#pragma once
#include <cstdint>

#include "kernels/activation.h"
#include "kernels/kernel_table.h"

namespace ampi::neon {

void add(const float* a, const float* b, int64_t n, ActivationSpec act, float* out);
void activate_inplace(float* x, int64_t n, ActivationSpec act);

// Channel operations (channels_neon.cpp) and 2x resampling (resample_neon.cpp); contracts
// in kernels/kernel_table.h.
void gated_output(const float* in, int64_t pixels, int c, ActivationSpec act, float* out);
void concat_channels(const float* a, int ca, const float* b, int cb, int64_t pixels, float* out);
void channel_sum(const float* in, int64_t pixels, int c, float* sum);
void dense(const float* w, const float* bias, int rows, int cols, const float* x,
           ActivationSpec act, float* y);
void haar_dwt(const float* in, int h, int w, int c, int row_begin, int row_end, float* out);
void haar_idwt(const float* in, int h, int w, int c, int row_begin, int row_end, float* out);
void resize2x_nearest(const float* in, int h, int w, int c, int row_begin, int row_end, float* out);
void resize2x_bilinear(const float* in, int h, int w, int c, int row_begin, int row_end, float* out);

// Convolution micro-kernels (conv_gemm_neon.cpp: 8x8 GEMM tile;
// conv_depthwise_neon.cpp); contracts in kernels/kernel_table.h.
constexpr int kGemmMr = 8, kGemmNr = 8;
void gemm_8x8(const GemmArgs& args);
void depthwise_row(const DepthwiseRowArgs& args);

}  // namespace ampi::neon
