// Scalar GEMM tile: the fallback of the scalar table, and the plainest statement of the
// gemm contract in kernels/kernel_table.h.
#include <algorithm>

#include "kernels/reference/reference.h"

namespace ampi::reference {

void gemm(const GemmArgs& g) {
  const int64_t panel_floats = static_cast<int64_t>(1 + g.k) * kGemmNr;
  const float* panel = g.packed;
  for (int j0 = 0; j0 < g.n; j0 += kGemmNr, panel += panel_floats) {
    const int columns = std::min(kGemmNr, g.n - j0);
    for (int i = 0; i < g.m; ++i) {
      float acc[kGemmNr];
      std::copy(panel, panel + kGemmNr, acc);
      const float* a = g.a + i * g.a_stride;
      const float* b = panel + kGemmNr;
      for (int kk = 0; kk < g.k; ++kk, b += kGemmNr)
        for (int j = 0; j < kGemmNr; ++j) acc[j] += a[kk] * b[j];
      float* c = g.c + i * g.c_stride + j0;
      const float* r = g.residual ? g.residual + i * g.c_stride + j0 : nullptr;
      for (int j = 0; j < columns; ++j) c[j] = ampi::activate(acc[j], g.act) + (r ? r[j] : 0.0f);
    }
  }
}

}  // namespace ampi::reference
