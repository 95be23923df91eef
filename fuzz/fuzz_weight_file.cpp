// libFuzzer target: the .ampw weight file reader (WeightFile::from_bytes), then every
// accessor a network loader uses on a file that passed validation.
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "fuzz/fuzz_support.h"
#include "weights_format/weight_file.h"

using ampi::fuzz::require;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ampi::fuzz::init_target();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const ampi::WeightFile file = ampi::WeightFile::from_bytes(std::vector<uint8_t>(data, data + size), "fuzz.ampw");
    for (const auto& row : file.metadata_rows()) require(!row[0].empty(), "metadata key is empty");
    for (const ampi::TensorInfo& info : file.tensors()) {
      // Validation promised that every tensor lies aligned inside the file.
      require(info.offset % ampi::ampw::kAlignment == 0, "tensor offset not aligned");
      require(info.offset <= size && info.bytes <= size - info.offset, "tensor outside the file");
      require(file.find(info.name) != nullptr, "listed tensor not found by name");
      const ampi::Tensor values = file.tensor(info.name, info.shape);
      require(values.numel() == ampi::shape_numel(info.shape), "tensor element count");
    }
  } catch (const std::runtime_error&) {
    // A rejected file: the expected outcome for almost every input.
  }
  return 0;
}
