// The plain matrix product the GEMM op (kernels/gemm.h) is tested against, on every
// instruction set and every way of passing B. Deliberately the plainest loop nest.
#pragma once
#include "kernels/gemm.h"

namespace ampi::reference {

// C[i][j] = act(bias[j] + sum_kk A[i][kk] * B[kk][j]) (+ R[i][j]), one output at a time,
// summed in double, with gemm.h's operand layouts (residual laid out like C; bias may be
// nullptr). Expects valid sizes and strides; C must not overlap A, B or the residual.
void gemm_direct(const GemmProblem& p, StridedMatrix b, const float* bias);

}  // namespace ampi::reference
