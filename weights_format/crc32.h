// CRC-32 as used by zlib, gzip and PNG (IEEE 802.3 polynomial, reflected, initial value
// and final xor 0xFFFFFFFF), so the Python side computes the same value with zlib.crc32.
// The .ampw format checksums its header and every tensor with it (see SPEC.md for why).
#pragma once
#include <cstddef>
#include <cstdint>

namespace ampi {

// Table-driven, sixteen bytes per step ("slicing-by-16"): over 1 GB/s even on a busy
// machine, so checking every tensor at load time costs little next to reading the file.
uint32_t crc32(const void* data, size_t size);

// Bit-at-a-time definition of the same function: the reference the fast one is tested
// against.
uint32_t crc32_reference(const void* data, size_t size);

}  // namespace ampi
