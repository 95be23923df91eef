// The dispatch tables hold what the kernel lists claim (kernels/kernel_list.def,
// slicing/row_kernel_list.def): on every runnable ISA, each family the list gives that
// ISA a variant of runs that very variant, not the reference nor another ISA's, and every
// other family runs what it falls back to; the table's record of who provides each entry
// says the same. The equivalence tests ("every ISA equals the reference") cannot see a
// table that quietly runs the reference: this one can, and the last cases show it does.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "engine/isa.h"
#include "kernels/kernel_table.h"
#include "kernels/reference/reference.h"
#include "slicing/row_kernels.h"
#if defined(AMPI_ARCH_X86)
#include "kernels/x86/avx2_kernels.h"
#include "kernels/x86/avx512_kernels.h"
#endif
#if defined(AMPI_ARCH_ARM64)
#include "kernels/arm/neon_kernels.h"
#endif

using namespace ampi;

namespace {

constexpr int kIsas = 4;  // Isa::Scalar .. Isa::Neon, indexed by their value

// Each ISA's own variants as the list claims them, straight from the ISA's namespace;
// nullptr where it has none (and for every ISA this architecture does not build).
KernelTable own_core_variants(Isa isa) {
  KernelTable t;
  switch (isa) {
    case Isa::Scalar:
#define AMPI_KERNEL(name, ...) t.name = reference::name;
#include "kernels/kernel_list.def"
      t.gemm_mr = reference::kGemmMr, t.gemm_nr = reference::kGemmNr;
      break;
#if defined(AMPI_ARCH_X86)
    case Isa::Avx2:
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_avx2(t.name = avx2::name;)
#include "kernels/kernel_list.def"
      t.gemm_mr = avx2::kGemmMr, t.gemm_nr = avx2::kGemmNr;
      break;
    case Isa::Avx512:
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_avx512(t.name = avx512::name;)
#include "kernels/kernel_list.def"
      t.gemm_mr = avx512::kGemmMr, t.gemm_nr = avx512::kGemmNr;
      break;
#endif
#if defined(AMPI_ARCH_ARM64)
    case Isa::Neon:
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_neon(t.name = neon::name;)
#include "kernels/kernel_list.def"
      t.gemm_mr = neon::kGemmMr, t.gemm_nr = neon::kGemmNr;
      break;
#endif
    default: break;
  }
  return t;
}

slicing::SlicingKernels own_slicing_variants(Isa isa) {
  slicing::SlicingKernels t;
  switch (isa) {
    case Isa::Scalar:
#define AMPI_KERNEL(name, ...) t.name = slicing::scalar::name;
#include "slicing/row_kernel_list.def"
      break;
#if defined(AMPI_ARCH_X86)
    case Isa::Avx2:
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_avx2(t.name = slicing::avx2::name;)
#include "slicing/row_kernel_list.def"
      break;
    case Isa::Avx512:
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_avx512(t.name = slicing::avx512::name;)
#include "slicing/row_kernel_list.def"
      break;
#endif
#if defined(AMPI_ARCH_ARM64)
    case Isa::Neon:
#define AMPI_KERNEL(name, return_type, parameters, in_avx2, in_avx512, in_neon) \
  AMPI_KERNEL_IF_##in_neon(t.name = slicing::neon::name;)
#include "slicing/row_kernel_list.def"
      break;
#endif
    default: break;
  }
  return t;
}

// Adds the family's name to `wrong` unless a table for table_isa runs, and records,
// the variant the list says it runs: the ISA's own where claimed, else its fallback's.
template <class Fn>
void check_entry(const KernelFamily& family, Isa table_isa, Fn got, Isa recorded, const Fn (&own)[kIsas],
                 std::vector<std::string>& wrong) {
  const Isa expected = kernel_provider(family, table_isa);
  const Fn reference = own[static_cast<int>(Isa::Scalar)];
  const bool right = got != nullptr && got == own[static_cast<int>(expected)] && recorded == expected &&
                     (expected == Isa::Scalar || got != reference);
  if (!right) wrong.push_back(family.name);
}

// The families of a core table that do not run what kernels/kernel_list.def claims
// ("gemm tile" when the tile is not that of the gemm kernel's ISA).
std::vector<std::string> core_mismatches(const KernelTable& t) {
  const KernelTable own[kIsas] = {own_core_variants(Isa::Scalar), own_core_variants(Isa::Avx2),
                                  own_core_variants(Isa::Avx512), own_core_variants(Isa::Neon)};
  const std::vector<KernelFamily>& families = kernel_families();
  std::vector<std::string> wrong;
  size_t i = 0;
#define AMPI_KERNEL(name, ...)                                                                      \
  check_entry<decltype(t.name)>(families.at(i++), t.isa, t.name, t.provided_by.name,                \
                                {own[0].name, own[1].name, own[2].name, own[3].name}, wrong);
#include "kernels/kernel_list.def"
  const KernelTable& tile = own[static_cast<int>(t.provided_by.gemm)];
  if (t.gemm_mr != tile.gemm_mr || t.gemm_nr != tile.gemm_nr) wrong.push_back("gemm tile");
  return wrong;
}

std::vector<std::string> slicing_mismatches(const slicing::SlicingKernels& t) {
  const slicing::SlicingKernels own[kIsas] = {own_slicing_variants(Isa::Scalar), own_slicing_variants(Isa::Avx2),
                                              own_slicing_variants(Isa::Avx512), own_slicing_variants(Isa::Neon)};
  const std::vector<KernelFamily>& families = slicing::slicing_kernel_families();
  std::vector<std::string> wrong;
  size_t i = 0;
#define AMPI_KERNEL(name, ...)                                                                      \
  check_entry<decltype(t.name)>(families.at(i++), t.isa, t.name, t.provided_by.name,                \
                                {own[0].name, own[1].name, own[2].name, own[3].name}, wrong);
#include "slicing/row_kernel_list.def"
  return wrong;
}

// The ISAs with a table of their own code: every runnable one but scalar.
std::vector<Isa> vector_isas() {
  std::vector<Isa> isas;
  for (Isa isa : runnable_isas())
    if (isa != Isa::Scalar) isas.push_back(isa);
  return isas;
}

}  // namespace

TEST_CASE("every runnable core table runs the variants kernels/kernel_list.def claims") {
  for (Isa isa : runnable_isas()) {
    INFO("isa " << isa_name(isa));
    const KernelTable& t = kernels_for(isa);
    CHECK(t.isa == isa);
    CHECK(core_mismatches(t).empty());
  }
}

TEST_CASE("every runnable slicing table runs the variants slicing/row_kernel_list.def claims") {
  for (Isa isa : runnable_isas()) {
    INFO("isa " << isa_name(isa));
    const slicing::SlicingKernels t = slicing::slicing_kernels(isa);
    CHECK(t.isa == isa);
    CHECK(slicing_mismatches(t).empty());
  }
}

TEST_CASE("kernel_entries names every family of the list with the table's provider, in order") {
  for (Isa isa : runnable_isas()) {
    const std::vector<KernelEntry> entries = kernel_entries(kernels_for(isa));
    const std::vector<KernelFamily>& families = kernel_families();
    REQUIRE(entries.size() == families.size());
    for (size_t i = 0; i < entries.size(); ++i) {
      INFO("isa " << isa_name(isa) << ", " << families[i].name);
      CHECK(std::string(entries[i].name) == families[i].name);
      CHECK(entries[i].provider == kernel_provider(families[i], isa));
    }
    const std::vector<KernelEntry> rows = slicing::slicing_kernel_entries(slicing::slicing_kernels(isa));
    REQUIRE(rows.size() == slicing::slicing_kernel_families().size());
    for (size_t i = 0; i < rows.size(); ++i)
      CHECK(rows[i].provider == kernel_provider(slicing::slicing_kernel_families()[i], isa));
  }
}

TEST_CASE("the fallback rule: AVX-512 runs AVX2's variant where it has none, the rest the reference") {
  const KernelFamily only_avx2{"f", true, false, false};
  CHECK(kernel_provider(only_avx2, Isa::Avx512) == Isa::Avx2);
  CHECK(kernel_provider(only_avx2, Isa::Avx2) == Isa::Avx2);
  CHECK(kernel_provider(only_avx2, Isa::Neon) == Isa::Scalar);
  const KernelFamily none{"g", false, false, false};
  for (Isa isa : {Isa::Scalar, Isa::Avx2, Isa::Avx512, Isa::Neon}) CHECK(kernel_provider(none, isa) == Isa::Scalar);
}

TEST_CASE("a table that keeps the reference or another ISA's code for a claimed family fails the check") {
  const std::vector<Isa> isas = vector_isas();
  if (isas.empty()) return;  // only the scalar table runs here: nothing can fall back
  const KernelTable& scalar = kernels_for(Isa::Scalar);
  for (Isa isa : isas) {
    INFO("isa " << isa_name(isa));
    KernelTable forgotten = kernels_for(isa);
    forgotten.gemm = scalar.gemm;  // a forgotten registration: the reference runs
    CHECK(core_mismatches(forgotten) == std::vector<std::string>{"gemm"});
    KernelTable misrecorded = kernels_for(isa);
    misrecorded.provided_by.dense = Isa::Scalar;
    CHECK(core_mismatches(misrecorded) == std::vector<std::string>{"dense"});
    KernelTable wrong_tile = kernels_for(isa);
    wrong_tile.gemm_mr = scalar.gemm_mr + 1;
    CHECK(core_mismatches(wrong_tile) == std::vector<std::string>{"gemm tile"});
    slicing::SlicingKernels rows = slicing::slicing_kernels(isa);
    rows.snap_row = slicing::slicing_kernels(Isa::Scalar).snap_row;
    CHECK(slicing_mismatches(rows) == std::vector<std::string>{"snap_row"});
  }
  if (isa_runnable(Isa::Avx2) && isa_runnable(Isa::Avx512)) {
    KernelTable narrower = kernels_for(Isa::Avx512);
    narrower.haar_dwt = kernels_for(Isa::Avx2).haar_dwt;  // AVX2's where AVX-512 has its own
    CHECK(core_mismatches(narrower) == std::vector<std::string>{"haar_dwt"});
  }
}
