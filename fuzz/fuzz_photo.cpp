// libFuzzer target: the photo decoder (read_photo: file checks, truncation checks, the
// header's dimensions against the memory budget, OpenCV's decoders).
#include <cstdint>
#include <opencv2/core/utils/logger.hpp>
#include <stdexcept>

#include "fuzz/fuzz_support.h"
#include "pipeline/photo_io.h"

using ampi::fuzz::require;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ampi::fuzz::init_target();
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = ampi::fuzz::write_scratch_file("photo", data, size);
  try {
    const cv::Mat image = ampi::read_photo(path);
    require(image.type() == CV_8UC3, "photo is not 8-bit BGR");
    require(image.cols >= ampi::kMinPhotoSide && image.rows >= ampi::kMinPhotoSide, "photo below the minimum size");
  } catch (const std::runtime_error&) {
    // A rejected file.
  }
  return 0;
}
