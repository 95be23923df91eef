#include <catch2/catch.hpp>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "weights_format/crc32.h"

using namespace ampi;

TEST_CASE("crc32 matches the published check values") {
  const char* check = "123456789";  // the standard CRC-32 check input
  CHECK(crc32(check, 9) == 0xCBF43926u);
  CHECK(crc32_reference(check, 9) == 0xCBF43926u);
  CHECK(crc32("", 0) == 0u);
  const char* fox = "The quick brown fox jumps over the lazy dog";
  CHECK(crc32(fox, std::strlen(fox)) == 0x414FA339u);  // zlib.crc32 of the same bytes
}

TEST_CASE("crc32 slicing-by-16 agrees with the bitwise reference at every length and alignment") {
  const uint32_t seed = 20240611;
  INFO("seed " << seed);
  std::mt19937 rng(seed);
  std::vector<uint8_t> bytes(300);
  for (uint8_t& b : bytes) b = static_cast<uint8_t>(rng());
  for (size_t start = 0; start < 8; ++start)
    for (size_t len = 0; start + len <= bytes.size(); len += 1 + len / 8) {
      INFO("start " << start << " length " << len);
      REQUIRE(crc32(bytes.data() + start, len) == crc32_reference(bytes.data() + start, len));
    }
}
