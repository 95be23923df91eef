// A process-wide memory budget: before ampi allocates something whose size comes from
// its input (a decoded photo, the layers of an MPI, a network's activation arena), it
// asks check_allocation() first. An input too big for the machine then ends with one
// line naming the file, the size and the budget, instead of the kernel's OOM killer
// ending the process halfway through (or swapping it to a crawl).
//
// The budget, in order of precedence: set_memory_budget() (tests, embedding programs),
// the environment variable AMPI_MEMORY_BUDGET ("2G", "512M", "1.5GiB", "1073741824"),
// half of the physical memory (ampi's largest single buffers are the MPI layers; the
// other half is left for everything else alive beside them), or 4 GiB when the physical
// memory cannot be read.
#pragma once
#include <cstdint>
#include <initializer_list>
#include <stdexcept>
#include <string>

namespace ampi {

constexpr uint64_t kFallbackMemoryBudget = uint64_t(4) << 30;
constexpr const char* kMemoryBudgetVariable = "AMPI_MEMORY_BUDGET";

// What check_allocation throws: a std::runtime_error, so callers that report any
// runtime_error report it too, and a type of its own for tests and callers that want to
// tell "too big" from "broken".
class MemoryBudgetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "2G", "2g", "2GB", "2GiB", "1.5G", "512M", "64K", "1073741824" (bytes). Units are
// binary (K = 1024). Throws std::invalid_argument naming the text and the problem.
uint64_t parse_byte_size(const std::string& text);

// "17.9 GiB", "512.0 MiB", "64.0 KiB", "100 bytes".
std::string format_bytes(uint64_t bytes);

// The budget in bytes (see above). Throws std::runtime_error when AMPI_MEMORY_BUDGET is
// set but is not a size.
uint64_t memory_budget();
// Overrides the environment and the default for the whole process; 0 removes the
// override.
void set_memory_budget(uint64_t bytes);

// The product of `factors`, saturating at UINT64_MAX, so that sizes computed from
// untrusted dimensions cannot wrap around to a small number.
uint64_t bytes_for(std::initializer_list<uint64_t> factors);

// Throws MemoryBudgetError("ORIGIN: needs 17.9 GiB for WHAT, over the 4.0 GiB memory
// budget (AMPI_MEMORY_BUDGET)") when `bytes` exceed memory_budget(). `origin` names the
// input responsible (a file), `what` the allocation ("8 RGBA layers at 30000x20000").
void check_allocation(uint64_t bytes, const std::string& origin, const std::string& what);

}  // namespace ampi
