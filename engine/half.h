// IEEE 754 half precision <-> float, portable bit manipulation (round to nearest even).
// Used for f16 weight storage; the arithmetic is always f32.
#pragma once
#include <cstdint>

namespace ampi {

uint16_t float_to_half(float value);
float half_to_float(uint16_t bits);

}  // namespace ampi
