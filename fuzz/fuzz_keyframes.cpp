// libFuzzer target: the keyframe file reader (read_keyframes), then the camera path it
// drives (keyframe_path at 30 fps), as `ampi render` uses them.
#include <cmath>
#include <cstdint>
#include <opencv2/core/utils/logger.hpp>
#include <stdexcept>

#include "fuzz/fuzz_support.h"
#include "render/trajectory.h"

using ampi::fuzz::require;

namespace {

bool finite_pose(const ampi::Pose& pose) {
  for (int i = 0; i < 9; ++i)
    if (!std::isfinite(pose.R.val[i])) return false;
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(pose.t[i])) return false;
  return std::isfinite(pose.zoom);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ampi::fuzz::init_target();
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = ampi::fuzz::write_scratch_file("keyframes.json", data, size);
  std::vector<ampi::Keyframe> keyframes;
  try {
    keyframes = ampi::read_keyframes(path);
  } catch (const std::runtime_error&) {
    return 0;  // a rejected file
  }
  require(!keyframes.empty(), "no keyframes returned");
  for (const ampi::Keyframe& k : keyframes) require(std::isfinite(k.time) && finite_pose(k.pose), "keyframe not finite");
  try {
    for (const ampi::Pose& pose : ampi::keyframe_path(keyframes, 30)) require(finite_pose(pose), "path pose not finite");
  } catch (const std::invalid_argument&) {
    // A path longer than kMaxPathFrames: keyframe_path's documented refusal.
  }
  return 0;
}
