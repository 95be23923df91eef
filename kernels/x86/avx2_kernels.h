// AVX2 + FMA micro-kernels (8 floats per vector). Declarations only: the definitions
// are compiled with -mavx2 -mfma in *_avx2.cpp files.
#pragma once
#include <cstdint>

#include "kernels/activation.h"
#include "kernels/kernel_table.h"

namespace ampi::avx2 {

void add(const float* a, const float* b, int64_t n, ActivationSpec act, float* out);
void activate_inplace(float* x, int64_t n, ActivationSpec act);

// Channel operations (channels_avx2.cpp) and 2x resampling (resample_avx2.cpp); contracts
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

// Convolution micro-kernels (conv_gemm_avx2.cpp: 6x16 GEMM tile;
// conv_depthwise_avx2.cpp); contracts in kernels/kernel_table.h.
constexpr int kGemmMr = 6, kGemmNr = 16;
void gemm_6x16(const GemmArgs& args);
void depthwise_row(const DepthwiseRowArgs& args);

}  // namespace ampi::avx2
