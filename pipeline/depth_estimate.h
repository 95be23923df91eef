// Disparity for a photo from the depth network, at a working resolution that keeps the
// network's cost bounded however large the photo is.
#pragma once
#include <opencv2/core.hpp>

#include "engine/thread_pool.h"
#include "nets/depth_model.h"

namespace ampi {

// bgr: CV_8UC3. Runs `net` on the photo resized (area-averaged) so its long side is at
// most max_side, never upscaled. Returns CV_32FC1 disparity (larger = nearer) at that
// working resolution; callers resize it to whatever resolution they need.
cv::Mat estimate_disparity(DepthModel& net, const cv::Mat& bgr, int max_side,
                           ThreadPool& pool = default_pool());

}  // namespace ampi
