#include "render/composite_kernels.h"

#include <stdexcept>
#include <string>

namespace ampi::render {

CompositeKernels composite_kernels(Isa isa) {
  if (!isa_runnable(isa))
    throw std::runtime_error(std::string("compositor kernels for ") + isa_name(isa) +
                             " are not runnable on this CPU or build");
  switch (isa) {
#if defined(__x86_64__)
    case Isa::Avx2:
    case Isa::Avx512:  // no wider variant: AVX-512 CPUs run the AVX2 one
      return {isa, avx2::warp_over_row, avx2::accum_to_bgr};
#endif
#if defined(__aarch64__)
    case Isa::Neon: return {isa, neon::warp_over_row, neon::accum_to_bgr};
#endif
    default: return {Isa::Scalar, scalar::warp_over_row, scalar::accum_to_bgr};
  }
}

}  // namespace ampi::render
