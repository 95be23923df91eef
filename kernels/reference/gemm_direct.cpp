#include "kernels/reference/gemm_reference.h"

namespace ampi::reference {

void gemm_direct(const GemmProblem& p, StridedMatrix b, const float* bias) {
  for (int i = 0; i < p.m; ++i)
    for (int j = 0; j < p.n; ++j) {
      double sum = bias ? bias[j] : 0.0;
      for (int kk = 0; kk < p.k; ++kk) {
        const float a = p.a[i * p.a_stride + kk];
        const float bv = b.transposed ? b.data[j * b.stride + kk] : b.data[kk * b.stride + j];
        sum += static_cast<double>(a) * bv;
      }
      const int64_t o = i * p.c_stride + j;
      const float y = ampi::activate(static_cast<float>(sum), p.act);
      p.c[o] = p.residual ? y + p.residual[o] : y;
    }
}

}  // namespace ampi::reference
