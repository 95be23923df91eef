#include "weights_format/crc32.h"

namespace ampi {
namespace {

constexpr uint32_t kPolynomial = 0xEDB88320u;  // 0x04C11DB7 bit-reversed

// kTables[0] is the classic byte table; kTables[s][b] is the CRC contribution of byte b
// followed by s zero bytes, which lets one step fold sixteen input bytes at once.
constexpr int kSlices = 16;
struct Crc32Tables {
  uint32_t t[kSlices][256];
};

constexpr Crc32Tables make_tables() {
  Crc32Tables tables{};
  for (uint32_t b = 0; b < 256; ++b) {
    uint32_t c = b;
    for (int bit = 0; bit < 8; ++bit) c = (c >> 1) ^ (kPolynomial & (0u - (c & 1u)));
    tables.t[0][b] = c;
  }
  for (int s = 1; s < kSlices; ++s)
    for (uint32_t b = 0; b < 256; ++b)
      tables.t[s][b] = (tables.t[s - 1][b] >> 8) ^ tables.t[0][tables.t[s - 1][b] & 0xFFu];
  return tables;
}

constexpr Crc32Tables kTables = make_tables();

inline uint32_t load_le32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

}  // namespace

uint32_t crc32(const void* data, size_t size) {
  const auto* p = static_cast<const uint8_t*>(data);
  const auto& t = kTables.t;
  uint32_t crc = 0xFFFFFFFFu;
  for (; size >= kSlices; p += kSlices, size -= kSlices) {
    // The running CRC folds into the first four bytes; the other twelve only add their
    // own table entries, so the sixteen lookups are independent of each other.
    const uint32_t first = load_le32(p) ^ crc;
    crc = t[15][first & 0xFF] ^ t[14][(first >> 8) & 0xFF] ^ t[13][(first >> 16) & 0xFF] ^ t[12][first >> 24];
    for (int i = 4; i < kSlices; ++i) crc ^= t[kSlices - 1 - i][p[i]];
  }
  for (; size > 0; ++p, --size) crc = t[0][(crc ^ *p) & 0xFF] ^ (crc >> 8);
  return crc ^ 0xFFFFFFFFu;
}

uint32_t crc32_reference(const void* data, size_t size) {
  const auto* p = static_cast<const uint8_t*>(data);
  uint32_t crc = 0xFFFFFFFFu;
  for (size_t i = 0; i < size; ++i) {
    crc ^= p[i];
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (kPolynomial & (0u - (crc & 1u)));
  }
  return crc ^ 0xFFFFFFFFu;
}

}  // namespace ampi
