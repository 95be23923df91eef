// The naive direct convolution: the definition every convolution path and every
// instruction set is tested against. Deliberately the plainest loop nest there is.
#pragma once
#include "kernels/conv.h"

namespace ampi::reference {

// out = act(conv(in) + bias) + residual with kernels/conv.h's layouts, one output value
// at a time, summed in double. bias and residual may be nullptr. Expects validated params
// and an input the dilated kernel fits in.
void conv2d_direct(const ConvParams& p, const float* in, int in_h, int in_w, const float* weights,
                   const float* bias, const float* residual, float* out);

}  // namespace ampi::reference
