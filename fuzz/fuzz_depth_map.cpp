// libFuzzer target: the depth-map importer (read_depth_map). The first input byte picks
// the file name's extension (which decides between the .npy reader and OpenCV's image
// decoders) and whether the values are distances; the rest is the file.
#include <cstdint>
#include <opencv2/core/utils/logger.hpp>
#include <stdexcept>
#include <string>

#include "fuzz/fuzz_support.h"
#include "pipeline/depth_io.h"

using ampi::fuzz::require;

namespace {

const char* const kNames[] = {"depth.png", "depth.npy", "depth.tiff", "depth.pgm"};

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ampi::fuzz::init_target();
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string path = ampi::fuzz::write_scratch_file(kNames[data[0] & 3], data + 1, size - 1);
  const bool is_distance = (data[0] & 4) != 0;
  try {
    const cv::Mat disparity = ampi::read_depth_map(path, is_distance);
    require(disparity.type() == CV_32FC1 && !disparity.empty(), "depth map is not a non-empty CV_32FC1 map");
    require(cv::checkRange(disparity), "depth map holds NaN or infinite values");
    if (is_distance) {
      double lowest = 0;
      cv::minMaxLoc(disparity, &lowest);
      require(lowest > 0, "inverted distances are not positive");
    }
  } catch (const std::runtime_error&) {
    // A rejected file.
  }
  return 0;
}
