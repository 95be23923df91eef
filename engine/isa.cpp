#include "engine/isa.h"

#include <cstdlib>
#include <stdexcept>

#include "engine/cpu_features.h"

namespace ampi {

const char* isa_name(Isa isa) {
  switch (isa) {
    case Isa::Scalar: return "scalar";
    case Isa::Avx2: return "avx2";
    case Isa::Avx512: return "avx512";
    case Isa::Neon: return "neon";
  }
  return "?";
}

Isa parse_isa(const std::string& name) {
  for (Isa isa : {Isa::Scalar, Isa::Avx2, Isa::Avx512, Isa::Neon})
    if (name == isa_name(isa)) return isa;
  throw std::invalid_argument("unknown instruction set '" + name +
                              "' (expected scalar, avx2, avx512 or neon)");
}

bool isa_runnable(Isa isa) {
  const CpuFeatures& f = cpu_features();
  switch (isa) {
    case Isa::Scalar: return true;
#if defined(AMPI_ARCH_X86)
    case Isa::Avx2: return f.avx2 && f.fma && f.f16c;
    case Isa::Avx512: return f.avx512f && f.avx512bw && f.avx512vl && f.avx512dq && f.f16c;
#endif
#if defined(AMPI_ARCH_ARM64)
    case Isa::Neon: return f.neon;
#endif
    default: return false;
  }
}

std::vector<Isa> runnable_isas() {
  std::vector<Isa> list;
  for (Isa isa : {Isa::Scalar, Isa::Avx2, Isa::Avx512, Isa::Neon})
    if (isa_runnable(isa)) list.push_back(isa);
  return list;
}

Isa best_isa() { return runnable_isas().back(); }

Isa active_isa() {
  static const Isa chosen = [] {
    const char* forced = std::getenv("AMPI_ISA");
    if (!forced || !*forced) return best_isa();
    const Isa isa = parse_isa(forced);
    if (!isa_runnable(isa))
      throw std::runtime_error(std::string("AMPI_ISA=") + forced +
                               ": this CPU or build cannot run that instruction set");
    return isa;
  }();
  return chosen;
}

}  // namespace ampi
