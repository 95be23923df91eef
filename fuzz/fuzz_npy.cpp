// libFuzzer target: the .npy reader (parse_npy), as used by the fixture tests and the
// depth-map importer.
#include <cstdint>
#include <stdexcept>

#include "fuzz/fuzz_support.h"
#include "weights_format/npy.h"

using ampi::fuzz::require;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ampi::fuzz::init_target();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const ampi::Tensor array = ampi::parse_npy(data, size, "fuzz.npy");
    require(array.dtype() == ampi::DType::F32, "array is not f32");
    require(array.numel() >= 0 && array.numel() <= static_cast<int64_t>(size), "more elements than input bytes");
    // Touch every element: AddressSanitizer then checks the whole array lies in its
    // allocation.
    const float* values = array.numel() > 0 ? array.f32() : nullptr;
    float sum = 0;
    for (int64_t i = 0; i < array.numel(); ++i) sum += values[i];
    volatile float sink = sum;
    (void)sink;
  } catch (const std::runtime_error&) {
    // A rejected file.
  }
  return 0;
}
