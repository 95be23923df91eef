#include "engine/cpu_caches.h"

#include <fstream>
#include <map>
#include <string>

namespace ampi {
namespace {

// CPU 0's data and unified caches from /sys/devices/system/cpu/cpu0/cache/index*/.
std::map<int, size_t> read_data_caches() {
  std::map<int, size_t> caches;
  for (int index = 0; index < 8; ++index) {
    const std::string dir = "/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(index) + "/";
    std::ifstream level_file(dir + "level"), size_file(dir + "size"), type_file(dir + "type");
    int level = 0;
    size_t size = 0;
    std::string unit, type;
    if (!(level_file >> level) || !(size_file >> size) || size == 0) continue;
    size_file >> unit;
    if (type_file >> type && type == "Instruction") continue;
    const size_t scale = unit == "K" ? 1024 : unit == "M" ? 1024 * 1024 : 1;
    caches[level] = size * scale;
  }
  return caches;
}

}  // namespace

size_t cache_bytes(int level, size_t fallback) {
  static const std::map<int, size_t> caches = read_data_caches();
  if (caches.empty()) return fallback;
  if (level == 0) return caches.rbegin()->second;
  const auto found = caches.find(level);
  return found == caches.end() ? fallback : found->second;
}

}  // namespace ampi
