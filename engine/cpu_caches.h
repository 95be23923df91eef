// The data cache sizes of the CPU ampi runs on, which size the kernels' cache blocking.
#pragma once
#include <cstddef>

namespace ampi {

// Bytes of CPU 0's data (or unified) cache at `level` (1, 2, 3, ...), or of its highest
// level for level 0, as sysfs describes it ("2048K"); `fallback` when sysfs says nothing
// (no /sys, e.g. under qemu, or no such level). Not sysconf: glibc reads cpuid, which
// under KVM has said 384 MiB for a 32 MiB L3. Read once, on the first call.
size_t cache_bytes(int level, size_t fallback);

}  // namespace ampi
