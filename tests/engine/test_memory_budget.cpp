#include <catch2/catch.hpp>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

#include "engine/memory_budget.h"

using namespace ampi;

namespace {

constexpr uint64_t kGiB = uint64_t(1) << 30;
constexpr uint64_t kMiB = uint64_t(1) << 20;

// Sets AMPI_MEMORY_BUDGET (or unsets it for nullptr) and clears any override for the
// scope, restoring both after, so test cases do not leak the budget into each other.
class BudgetScope {
 public:
  explicit BudgetScope(const char* env_value) {
    if (const char* old = std::getenv(kMemoryBudgetVariable)) saved_ = old, had_ = true;
    if (env_value)
      setenv(kMemoryBudgetVariable, env_value, 1);
    else
      unsetenv(kMemoryBudgetVariable);
    set_memory_budget(0);
  }
  ~BudgetScope() {
    set_memory_budget(0);
    if (had_)
      setenv(kMemoryBudgetVariable, saved_.c_str(), 1);
    else
      unsetenv(kMemoryBudgetVariable);
  }

 private:
  std::string saved_;
  bool had_ = false;
};

}  // namespace

TEST_CASE("byte sizes parse with binary units") {
  CHECK(parse_byte_size("1073741824") == kGiB);
  CHECK(parse_byte_size("2G") == 2 * kGiB);
  CHECK(parse_byte_size("2g") == 2 * kGiB);
  CHECK(parse_byte_size("2GB") == 2 * kGiB);
  CHECK(parse_byte_size("2GiB") == 2 * kGiB);
  CHECK(parse_byte_size(" 512 M ") == 512 * kMiB);
  CHECK(parse_byte_size("1.5G") == 3 * kGiB / 2);
  CHECK(parse_byte_size("64K") == 65536);
  CHECK(parse_byte_size("1T") == 1024 * kGiB);
  CHECK(parse_byte_size("100b") == 100);
}

TEST_CASE("malformed byte sizes are rejected with the text in the message") {
  for (const char* bad : {"", "G", "two G", "2X", "2GG", "0", "0.1", "1.2.3G", "-1G", "1e3", "99999999999T"}) {
    INFO("input '" << bad << "'");
    CHECK_THROWS_AS(parse_byte_size(bad), std::invalid_argument);
  }
  CHECK_THROWS_WITH(parse_byte_size("2X"), Catch::Contains("'2X'") && Catch::Contains("unit"));
}

TEST_CASE("byte counts print in the largest binary unit") {
  CHECK(format_bytes(0) == "0 bytes");
  CHECK(format_bytes(1023) == "1023 bytes");
  CHECK(format_bytes(1024) == "1.0 KiB");
  CHECK(format_bytes(512 * kMiB) == "512.0 MiB");
  CHECK(format_bytes(uint64_t(30000) * 20000 * 4 * 8) == "17.9 GiB");
  CHECK(format_bytes(std::numeric_limits<uint64_t>::max()) == "16.0 EiB");
}

TEST_CASE("sizes from untrusted dimensions saturate instead of wrapping") {
  CHECK(bytes_for({8, 30000, 20000, 4}) == uint64_t(19200000000));
  CHECK(bytes_for({}) == 1);
  CHECK(bytes_for({uint64_t(1) << 40, uint64_t(1) << 30}) == std::numeric_limits<uint64_t>::max());
  CHECK(bytes_for({uint64_t(1) << 40, uint64_t(1) << 30, 0}) == 0);
}

TEST_CASE("the budget comes from the override, then the environment, then the machine") {
  SECTION("environment") {
    BudgetScope scope("2G");
    CHECK(memory_budget() == 2 * kGiB);
    set_memory_budget(3 * kMiB);
    CHECK(memory_budget() == 3 * kMiB);
  }
  SECTION("default: a positive share of the machine") {
    BudgetScope scope(nullptr);
    CHECK(memory_budget() > 0);
  }
  SECTION("a malformed variable is an error naming it") {
    BudgetScope scope("lots");
    CHECK_THROWS_WITH(memory_budget(), Catch::StartsWith("AMPI_MEMORY_BUDGET: ") && Catch::Contains("'lots'"));
  }
}

TEST_CASE("check_allocation passes sizes within the budget and names everything otherwise") {
  BudgetScope scope("4G");
  CHECK_NOTHROW(check_allocation(4 * kGiB, "photo.jpg", "the decoded photo"));
  CHECK_THROWS_AS(check_allocation(4 * kGiB + 1, "photo.jpg", "the decoded photo"), MemoryBudgetError);
  CHECK_THROWS_WITH(check_allocation(bytes_for({8, 30000, 20000, 4}), "photo.jpg", "8 RGBA layers at 30000x20000"),
                    "photo.jpg: needs 17.9 GiB for 8 RGBA layers at 30000x20000, over the 4.0 GiB memory budget "
                    "(AMPI_MEMORY_BUDGET)");
}
