#include "kernels/kernel_table.h"

#include <stdexcept>
#include <string>

namespace ampi {
namespace {

KernelTable build(Isa isa) {
  KernelTable table;
  fill_scalar_kernels(table);
  table.isa = isa;
  // The fill functions are compiled with their ISA's flags, so even filling the table may
  // execute that ISA's instructions (GCC stores the pointers with AVX-512 moves): never
  // call one the CPU cannot run. kernels_for() never hands out such a table.
  if (!isa_runnable(isa)) return table;
  switch (isa) {
    case Isa::Scalar: break;
#if defined(AMPI_ARCH_X86)
    case Isa::Avx2: fill_avx2_kernels(table); break;
    case Isa::Avx512:
      fill_avx2_kernels(table);  // AVX-512 CPUs run AVX2 code for ops without a wider variant
      fill_avx512_kernels(table);
      break;
#endif
#if defined(AMPI_ARCH_ARM64)
    case Isa::Neon: fill_neon_kernels(table); break;
#endif
    default: break;
  }
  return table;
}

}  // namespace

const KernelTable& kernels_for(Isa isa) {
  if (!isa_runnable(isa))
    throw std::runtime_error(std::string("kernels for ") + isa_name(isa) +
                             " are not runnable on this CPU or build");
  static const KernelTable tables[] = {build(Isa::Scalar), build(Isa::Avx2),
                                       build(Isa::Avx512), build(Isa::Neon)};
  return tables[static_cast<int>(isa)];
}

const KernelTable& kernels() {
  static const KernelTable& active = kernels_for(active_isa());
  return active;
}

}  // namespace ampi
