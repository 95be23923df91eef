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

// Takes the variants the list's column for `source` claims, and records them.
void take_variants(SlicingKernels& t, Isa source) {
  switch (source) {
#if defined(AMPI_ARCH_X86)
    case Isa::Avx2:
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_TAKE(t, avx2, Isa::Avx2, in_avx2, name)
#include "slicing/row_kernel_list.def"
      break;
    case Isa::Avx512:
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_TAKE(t, avx512, Isa::Avx512, in_avx512, name)
#include "slicing/row_kernel_list.def"
      break;
#endif
#if defined(AMPI_ARCH_ARM64)
    case Isa::Neon:
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_TAKE(t, neon, Isa::Neon, in_neon, name)
#include "slicing/row_kernel_list.def"
      break;
#endif
    default: break;
  }
}

}  // namespace

SlicingKernels slicing_kernels(Isa isa) {
  if (!isa_runnable(isa))
    throw std::runtime_error(std::string("slicing kernels for ") + isa_name(isa) +
                             " are not runnable on this CPU or build");
  SlicingKernels table = reference_table();
  table.isa = isa;
  for (Isa source : variant_sources(isa)) take_variants(table, source);
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
