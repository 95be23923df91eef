// What the kernel lists share: the core table's (kernels/kernel_list.def) and the
// slicer's (slicing/row_kernel_list.def) are written in one format,
//
//   AMPI_KERNEL(name, return type, (parameters), avx2, avx512, neon)
//
// each ISA column `yes` where that instruction set has a variant of its own and `no`
// where its table keeps the one it falls back to (AVX-512 to AVX2's where AVX2 has one,
// every other to the scalar reference, which every family has). A reader defines
// AMPI_KERNEL, includes the list, and the list undefines it.
#pragma once
#include <vector>

#include "engine/isa.h"

// AMPI_KERNEL_IF_##column(...) keeps its arguments where the column says yes and drops
// them where it says no.
#define AMPI_KERNEL_IF_yes(...) __VA_ARGS__
#define AMPI_KERNEL_IF_no(...)
// A list line's registration for one ISA: where `column` says yes, table.name takes
// ns::name and records `isa` as its provider (kernel_table.cpp, slicing/row_kernels.cpp).
#define AMPI_KERNEL_TAKE(table, ns, isa, column, name) \
  AMPI_KERNEL_IF_##column(table.name = ns::name; table.provided_by.name = isa;)
// A list line as a KernelFamily initialiser (with a comma): for kernel_families().
#define AMPI_KERNEL_CLAIM_yes true
#define AMPI_KERNEL_CLAIM_no false
#define AMPI_KERNEL_FAMILY(name, return_type, parameters, in_avx2, in_avx512, in_neon)              \
  ::ampi::KernelFamily{#name, AMPI_KERNEL_CLAIM_##in_avx2, AMPI_KERNEL_CLAIM_##in_avx512,                \
                       AMPI_KERNEL_CLAIM_##in_neon},

namespace ampi {

// A family as its list declares it: whether each ISA has a variant of its own.
struct KernelFamily {
  const char* name;
  bool avx2, avx512, neon;
  // Scalar: always (the reference is the scalar table's own).
  bool has_variant(Isa isa) const {
    switch (isa) {
      case Isa::Scalar: return true;
      case Isa::Avx2: return avx2;
      case Isa::Avx512: return avx512;
      case Isa::Neon: return neon;
    }
    return false;
  }
};

// The ISAs whose variants a table for `isa` takes over the scalar reference, in order,
// each overwriting the one before: AVX-512 CPUs run AVX2 code, so an AVX-512 table
// starts from AVX2's variants. Every table of both lists is built in this order.
inline std::vector<Isa> variant_sources(Isa isa) {
  if (isa == Isa::Avx512) return {Isa::Avx2, Isa::Avx512};
  if (isa == Isa::Scalar) return {};
  return {isa};
}

// The ISA whose code a table for `isa` runs for a family: the last of its variant
// sources that has a variant, else the scalar reference.
inline Isa kernel_provider(const KernelFamily& f, Isa isa) {
  Isa provider = Isa::Scalar;
  for (Isa source : variant_sources(isa))
    if (f.has_variant(source)) provider = source;
  return provider;
}

// What a table runs for one family, for code that walks every entry (tests, benchmarks).
struct KernelEntry {
  const char* name;
  Isa provider;
};

}  // namespace ampi
