// Scalar reference element-wise kernels.
#include "kernels/reference/reference.h"

namespace ampi::reference {

void add(const float* a, const float* b, int64_t n, ActivationSpec act, float* out) {
  for (int64_t i = 0; i < n; ++i) out[i] = ampi::activate(a[i] + b[i], act);
}

void activate(float* x, int64_t n, ActivationSpec act) {
  for (int64_t i = 0; i < n; ++i) x[i] = ampi::activate(x[i], act);
}

}  // namespace ampi::reference
