// libFuzzer target: the network loaders' checks of a weight file's metadata
// (nets/model_loader.h, the depth and inpainting builders), then one small forward pass
// of whatever they accept. The container's own checks have their target
// (fuzz_weight_file); here the header checksum is recomputed after mutation, so that
// mutated metadata reaches the loaders instead of stopping at the checksum. Seeds: the
// tiny depth (lite-style and Depth Anything V2) and inpainting networks of the test
// fixtures (fuzz/corpus/networks/).
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "fuzz/fuzz_support.h"
#include "nets/model_loader.h"
#include "weights_format/crc32.h"
#include "weights_format/weight_file.h"

using ampi::fuzz::require;

namespace {

// The header checksum sits right after the header (weights_format/SPEC.md).
void reseal_header(std::vector<uint8_t>& bytes) {
  if (bytes.size() < ampi::ampw::kPreambleBytes) return;
  uint64_t header_bytes = 0;
  std::memcpy(&header_bytes, bytes.data() + 16, 8);
  if (header_bytes < ampi::ampw::kPreambleBytes || header_bytes > bytes.size() - ampi::ampw::kChecksumBytes) return;
  const uint32_t crc = ampi::crc32(bytes.data(), header_bytes);
  std::memcpy(bytes.data() + header_bytes, &crc, 4);
}

void run_depth(const ampi::WeightFile& file) {
  const std::unique_ptr<ampi::DepthModel> net = ampi::load_depth_model(file);
  // A mutated depth.working_size would make a Depth Anything V2 file run a huge network:
  // the pass runs at most at 64 (a size the file's patch rules out is a rejection).
  if (net->working_size() > 64) {
    try {
      net->set_working_size(64);
    } catch (const std::invalid_argument&) {
      return;
    }
  }
  const int h = 9, w = 13;  // padded up to the network's multiple inside run()
  const std::vector<float> rgb(size_t(h) * w * 3, 0.5f);
  const ampi::Tensor out = net->run(rgb.data(), h, w);
  require(out.shape() == ampi::Shape{h, w}, "depth output is not the input's size");
}

void run_inpaint(const ampi::WeightFile& file) {
  const ampi::InpaintNet net = ampi::InpaintNet::from_file(file);
  const int side = net.multiple();
  std::vector<float> rgb(size_t(side) * side * 3, 0.25f), hole(size_t(side) * side, 0.0f), out(rgb.size());
  hole[0] = 1.0f;
  net.run(rgb.data(), hole.data(), side, side, out.data());
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ampi::fuzz::init_target();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<uint8_t> bytes(data, data + size);
  reseal_header(bytes);
  try {
    const ampi::WeightFile file = ampi::WeightFile::from_bytes(std::move(bytes), "fuzz.ampw");
    if (ampi::model_kind(file) == ampi::ModelKind::Depth)
      run_depth(file);
    else
      run_inpaint(file);
  } catch (const std::runtime_error&) {
    // A rejected file: the expected outcome for most inputs.
  }
  return 0;
}
