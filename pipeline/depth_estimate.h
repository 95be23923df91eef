// Disparity for a photo from the depth network, at a working resolution that keeps the
// network's cost bounded however large the photo is.
#pragma once
#include <opencv2/core.hpp>

#include "engine/thread_pool.h"
#include "nets/depth_model.h"

namespace ampi {

// bgr: CV_8UC3. Runs `net` at `working_size` (0: the size it has, by default its
// file's; DepthModel::set_working_size, which throws std::invalid_argument on a size the
// network cannot take) on the photo resized to net.input_size() with the tent filter
// its training used (tent_resize.h): the wavelet networks' long side at most the working
// size, never upscaled; Depth Anything V2 the photo as it is (it resizes inside).
// Returns CV_32FC1 disparity (larger = nearer) at that input size; callers resize it to
// whatever resolution they need.
cv::Mat estimate_disparity(DepthModel& net, const cv::Mat& bgr, int working_size,
                           ThreadPool& pool = default_pool());

// net.set_working_size(size) for a command-line option: a size the network cannot take
// becomes std::runtime_error "OPTION: working size N is not in A..B".
void set_working_size_option(DepthModel& net, int size, const char* option = "--working-size");

}  // namespace ampi
