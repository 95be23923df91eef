#include "engine/memory_budget.h"

#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>

namespace ampi {
namespace {

std::atomic<uint64_t> g_budget_override{0};

// Unit suffixes are case-insensitive and may be followed by "B" or "iB".
uint64_t unit_multiplier(std::string unit, const std::string& text) {
  for (char& c : unit) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (unit.empty() || unit == "b") return 1;
  static const char kPrefixes[] = "kmgt";
  for (int i = 0; i < 4; ++i) {
    if (unit[0] != kPrefixes[i]) continue;
    const std::string rest = unit.substr(1);
    if (rest.empty() || rest == "b" || rest == "ib") return uint64_t(1) << (10 * (i + 1));
  }
  throw std::invalid_argument("'" + text + "' has an unknown unit '" + unit + "' (use K, M, G or T)");
}

// Physical memory, lowered to the cgroup v2 limit when the process runs in a container
// with one (the OOM killer enforces that one, not the machine's size). 0 when unknown.
uint64_t available_physical_memory() {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page_size = sysconf(_SC_PAGE_SIZE);
  uint64_t bytes = pages > 0 && page_size > 0 ? uint64_t(pages) * uint64_t(page_size) : 0;
  std::ifstream cgroup("/sys/fs/cgroup/memory.max");
  uint64_t limit = 0;
  if (cgroup >> limit && limit > 0 && (bytes == 0 || limit < bytes)) bytes = limit;  // "max" fails >>
  return bytes;
}

uint64_t default_budget() {
  const uint64_t physical = available_physical_memory();
  return physical > 0 ? physical / 2 : kFallbackMemoryBudget;
}

}  // namespace

uint64_t parse_byte_size(const std::string& text) {
  size_t begin = 0, end = text.size();
  while (begin < end && std::isspace(static_cast<unsigned char>(text[begin]))) ++begin;
  while (end > begin && std::isspace(static_cast<unsigned char>(text[end - 1]))) --end;
  size_t number_end = begin;
  while (number_end < end && (std::isdigit(static_cast<unsigned char>(text[number_end])) || text[number_end] == '.'))
    ++number_end;
  if (number_end == begin) throw std::invalid_argument("'" + text + "' is not a size (examples: 2G, 512M, 1073741824)");
  const std::string number = text.substr(begin, number_end - begin);
  char* parsed_end = nullptr;
  const double value = std::strtod(number.c_str(), &parsed_end);
  if (parsed_end != number.c_str() + number.size())
    throw std::invalid_argument("'" + text + "' is not a size (examples: 2G, 512M, 1073741824)");
  size_t unit_begin = number_end;
  while (unit_begin < end && std::isspace(static_cast<unsigned char>(text[unit_begin]))) ++unit_begin;
  const double bytes = value * double(unit_multiplier(text.substr(unit_begin, end - unit_begin), text));
  if (!(bytes >= 1)) throw std::invalid_argument("'" + text + "' is not a positive size");
  // 2^64 is exactly representable; anything at or above it does not fit.
  if (bytes >= 18446744073709551616.0) throw std::invalid_argument("'" + text + "' is too large");
  return static_cast<uint64_t>(bytes);
}

std::string format_bytes(uint64_t bytes) {
  if (bytes < 1024) return std::to_string(bytes) + " bytes";
  static const char* const kUnits[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double value = double(bytes) / 1024;
  int unit = 0;
  while (value >= 1024 && unit < 5) {
    value /= 1024;
    ++unit;
  }
  char text[32];
  std::snprintf(text, sizeof text, "%.1f %s", value, kUnits[unit]);
  return text;
}

uint64_t memory_budget() {
  if (const uint64_t forced = g_budget_override.load(std::memory_order_relaxed)) return forced;
  const char* env = std::getenv(kMemoryBudgetVariable);
  if (env == nullptr || *env == '\0') return default_budget();
  try {
    return parse_byte_size(env);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string(kMemoryBudgetVariable) + ": " + e.what());
  }
}

void set_memory_budget(uint64_t bytes) { g_budget_override.store(bytes, std::memory_order_relaxed); }

uint64_t bytes_for(std::initializer_list<uint64_t> factors) {
  constexpr uint64_t kMax = std::numeric_limits<uint64_t>::max();
  uint64_t product = 1;
  bool saturated = false;  // kept going: a later zero factor still makes the product 0
  for (uint64_t f : factors) {
    if (f == 0) return 0;
    if (saturated || product > kMax / f)
      saturated = true;
    else
      product *= f;
  }
  return saturated ? kMax : product;
}

void check_allocation(uint64_t bytes, const std::string& origin, const std::string& what) {
  const uint64_t budget = memory_budget();
  if (bytes <= budget) return;
  throw MemoryBudgetError(origin + ": needs " + format_bytes(bytes) + " for " + what + ", over the " +
                          format_bytes(budget) + " memory budget (" + kMemoryBudgetVariable + ")");
}

}  // namespace ampi
