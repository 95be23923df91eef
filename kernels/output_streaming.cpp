#include "kernels/output_streaming.h"

#include <cstddef>

#include "engine/cpu_caches.h"

namespace ampi {
namespace {

// Outputs larger than this many last-level caches are streamed. Outputs that may still be
// cached when the next layer reads them keep plain stores: streaming a 12 MB output (3x3
// s2 over 512x384x64) measured 10% slower than plain stores with a 32 MB L3.
constexpr size_t kStreamOutputCaches = 1;
// When the system does not say (no sysfs cache description, e.g. under qemu).
constexpr size_t kDefaultLastLevelCacheBytes = size_t{32} << 20;

}  // namespace

bool stream_output(const float* out, int64_t floats, int64_t run_stride) {
  const bool whole_lines = reinterpret_cast<uintptr_t>(out) % 64 == 0 && run_stride % 16 == 0;
  const size_t bytes = static_cast<size_t>(floats) * sizeof(float);
  return whole_lines && bytes > kStreamOutputCaches * cache_bytes(0, kDefaultLastLevelCacheBytes);
}

}  // namespace ampi
