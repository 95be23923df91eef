// The tables, built from kernels/kernel_list.def: nothing here names a kernel family.
// Filling a table only takes the kernels' addresses, so this file is compiled for the
// baseline target and builds every table this architecture has; kernels_for() hands out
// only those the CPU runs.
#include "kernels/kernel_table.h"

#include <stdexcept>
#include <string>

#include "kernels/reference/reference.h"
#if defined(AMPI_ARCH_X86)
#include "kernels/x86/avx2_kernels.h"
#include "kernels/x86/avx512_kernels.h"
#endif
#if defined(AMPI_ARCH_ARM64)
#include "kernels/arm/neon_kernels.h"
#endif

namespace ampi {
namespace {

KernelTable reference_table() {
  KernelTable t;
#define AMPI_KERNEL(name, ...) t.name = reference::name;
#include "kernels/kernel_list.def"
  return t;
}

// Takes the variants the list's column for `source` claims, and records them.
void take_variants(KernelTable& t, Isa source) {
  switch (source) {
#if defined(AMPI_ARCH_X86)
    case Isa::Avx2:
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_TAKE(t, avx2, Isa::Avx2, in_avx2, name)
#include "kernels/kernel_list.def"
      break;
    case Isa::Avx512:
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_TAKE(t, avx512, Isa::Avx512, in_avx512, name)
#include "kernels/kernel_list.def"
      break;
#endif
#if defined(AMPI_ARCH_ARM64)
    case Isa::Neon:
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_TAKE(t, neon, Isa::Neon, in_neon, name)
#include "kernels/kernel_list.def"
      break;
#endif
    default: break;
  }
}

// The gemm tile is the shape the gemm kernel is written for: that of the ISA providing it.
void set_gemm_tile(KernelTable& t) {
  switch (t.provided_by.gemm) {
#if defined(AMPI_ARCH_X86)
    case Isa::Avx2: t.gemm_mr = avx2::kGemmMr, t.gemm_nr = avx2::kGemmNr; return;
    case Isa::Avx512: t.gemm_mr = avx512::kGemmMr, t.gemm_nr = avx512::kGemmNr; return;
#endif
#if defined(AMPI_ARCH_ARM64)
    case Isa::Neon: t.gemm_mr = neon::kGemmMr, t.gemm_nr = neon::kGemmNr; return;
#endif
    default: t.gemm_mr = reference::kGemmMr, t.gemm_nr = reference::kGemmNr; return;
  }
}

KernelTable build(Isa isa) {
  KernelTable table = reference_table();
  table.isa = isa;
  for (Isa source : variant_sources(isa)) take_variants(table, source);
  set_gemm_tile(table);
  return table;
}

}  // namespace

const KernelTable& kernels_for(Isa isa) {
  if (!isa_runnable(isa))
    throw std::runtime_error(std::string("kernels for ") + isa_name(isa) +
                             " are not runnable on this CPU or build");
  static const KernelTable tables[] = {build(Isa::Scalar), build(Isa::Avx2), build(Isa::Avx512),
                                       build(Isa::Neon)};
  return tables[static_cast<int>(isa)];
}

const KernelTable& kernels() {
  static const KernelTable& active = kernels_for(active_isa());
  return active;
}

const std::vector<KernelFamily>& kernel_families() {
  static const std::vector<KernelFamily> families = {
#define AMPI_KERNEL AMPI_KERNEL_FAMILY
#include "kernels/kernel_list.def"
  };
  return families;
}

std::vector<KernelEntry> kernel_entries(const KernelTable& table) {
  return {
#define AMPI_KERNEL(name, ...) {#name, table.provided_by.name},
#include "kernels/kernel_list.def"
  };
}

}  // namespace ampi
