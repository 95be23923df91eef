// engine/cpu_caches.h against sysfs read here by other means (sscanf of each cache's
// files), and its fallbacks.
#include <catch2/catch.hpp>
#include <cstdio>
#include <map>
#include <string>

#include "engine/cpu_caches.h"

using namespace ampi;

namespace {

// The first line of a file, or "" when it cannot be read.
std::string first_line(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "r");
  if (!f) return "";
  char buffer[64] = {};
  const bool read = std::fgets(buffer, sizeof buffer, f) != nullptr;
  std::fclose(f);
  return read ? buffer : "";
}

// Level -> bytes of CPU 0's data and unified caches, as sysfs lists them ("48K").
std::map<int, size_t> sysfs_caches() {
  std::map<int, size_t> caches;
  for (int index = 0; index < 8; ++index) {
    const std::string dir = "/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(index) + "/";
    int level = 0;
    unsigned long size = 0;
    char unit = 0;
    if (std::sscanf(first_line(dir + "level").c_str(), "%d", &level) != 1) continue;
    if (std::sscanf(first_line(dir + "size").c_str(), "%lu%c", &size, &unit) < 1 || size == 0) continue;
    if (first_line(dir + "type").rfind("Instruction", 0) == 0) continue;
    caches[level] = size * (unit == 'K' ? 1024ul : unit == 'M' ? 1024ul * 1024 : 1ul);
  }
  return caches;
}

}  // namespace

TEST_CASE("cache sizes are sysfs's data caches, the fallback where it names none") {
  const std::map<int, size_t> expected = sysfs_caches();
  constexpr size_t kFallback = 12345;
  CHECK(cache_bytes(9, kFallback) == kFallback);  // no CPU has a ninth level
  if (expected.empty()) {
    CHECK(cache_bytes(0, kFallback) == kFallback);
    CHECK(cache_bytes(1, kFallback) == kFallback);
    return;
  }
  for (const auto& [level, bytes] : expected) CHECK(cache_bytes(level, kFallback) == bytes);
  CHECK(cache_bytes(0, kFallback) == expected.rbegin()->second);  // the highest level
}
