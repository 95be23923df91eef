// The slicer's tables, built from slicing/row_kernel_list.def as kernels/kernel_table.cpp
// builds the core's: nothing here names a row kernel.
#include "slicing/row_kernels.h"

#include <stdexcept>
#include <string>

namespace ampi::slicing {
namespace {

SlicingKernels reference_table() {
  SlicingKernels t;
#define AMPI_KERNEL(name, ...) t.name = scalar::name;
#include "slicing/row_kernel_list.def"
  return t;
}

#if defined(AMPI_ARCH_X86)
void take_avx2_variants(SlicingKernels& t) {
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_avx2(t.name = avx2::name; t.provided_by.name = Isa::Avx2;)
#include "slicing/row_kernel_list.def"
}

void take_avx512_variants(SlicingKernels& t) {
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_avx512(t.name = avx512::name; t.provided_by.name = Isa::Avx512;)
#include "slicing/row_kernel_list.def"
}
#endif

#if defined(AMPI_ARCH_ARM64)
void take_neon_variants(SlicingKernels& t) {
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_neon(t.name = neon::name; t.provided_by.name = Isa::Neon;)
#include "slicing/row_kernel_list.def"
}
#endif

}  // namespace

SlicingKernels slicing_kernels(Isa isa) {
  if (!isa_runnable(isa))
    throw std::runtime_error(std::string("slicing kernels for ") + isa_name(isa) +
                             " are not runnable on this CPU or build");
  SlicingKernels table = reference_table();
  table.isa = isa;
  switch (isa) {
#if defined(AMPI_ARCH_X86)
    case Isa::Avx2: take_avx2_variants(table); break;
    case Isa::Avx512:
      take_avx2_variants(table);  // as the core tables: AVX2's where AVX-512 has none
      take_avx512_variants(table);
      break;
#endif
#if defined(AMPI_ARCH_ARM64)
    case Isa::Neon: take_neon_variants(table); break;
#endif
    default: break;
  }
  return table;
}

const std::vector<KernelFamily>& slicing_kernel_families() {
  static const std::vector<KernelFamily> families = {
#define AMPI_KERNEL AMPI_KERNEL_FAMILY
#include "slicing/row_kernel_list.def"
  };
  return families;
}

std::vector<KernelEntry> slicing_kernel_entries(const SlicingKernels& table) {
  return {
#define AMPI_KERNEL(name, ...) {#name, table.provided_by.name},
#include "slicing/row_kernel_list.def"
  };
}

}  // namespace ampi::slicing
