#include "slicing/row_kernels.h"

#include <stdexcept>
#include <string>

namespace ampi::slicing {

SlicingKernels slicing_kernels(Isa isa) {
  if (!isa_runnable(isa))
    throw std::runtime_error(std::string("slicing kernels for ") + isa_name(isa) +
                             " are not runnable on this CPU or build");
  switch (isa) {
#if defined(__x86_64__)
    case Isa::Avx2: return {isa, avx2::range_row, avx2::normalize_row, avx2::bilateral_weights, avx2::bilateral_combine, avx2::snap_row};
    case Isa::Avx512: return {isa, avx512::range_row, avx512::normalize_row, avx512::bilateral_weights, avx512::bilateral_combine, avx512::snap_row};
#endif
#if defined(__aarch64__)
    case Isa::Neon: return {isa, neon::range_row, neon::normalize_row, neon::bilateral_weights, neon::bilateral_combine, neon::snap_row};
#endif
    default: return {Isa::Scalar, scalar::range_row, scalar::normalize_row, scalar::bilateral_weights, scalar::bilateral_combine, scalar::snap_row};
  }
}

}  // namespace ampi::slicing
