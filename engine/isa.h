// Instruction-set variants of the kernels and which one runs. The choice is made once:
// the best variant the CPU supports, or the one named by AMPI_ISA
// (scalar|avx2|avx512|neon) so tests and benchmarks can force each variant.
#pragma once
#include <string>
#include <vector>

namespace ampi {

enum class Isa { Scalar, Avx2, Avx512, Neon };

const char* isa_name(Isa isa);
// Parses "scalar", "avx2", "avx512" or "neon"; throws std::invalid_argument otherwise.
Isa parse_isa(const std::string& name);

// Whether this binary contains the variant and this CPU can execute it.
bool isa_runnable(Isa isa);
// Every runnable variant, scalar first: the list tests iterate over.
std::vector<Isa> runnable_isas();
// The best runnable variant.
Isa best_isa();
// best_isa() unless AMPI_ISA names another; a forced variant the CPU cannot run is an
// error (std::runtime_error), never a silent fallback.
Isa active_isa();

}  // namespace ampi
