#include "pipeline/depth_estimate.h"

#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "pipeline/tent_resize.h"

namespace ampi {

cv::Mat estimate_disparity(DepthModel& net, const cv::Mat& bgr, int working_size, ThreadPool& pool) {
  if (bgr.type() != CV_8UC3 || bgr.empty())
    throw std::invalid_argument("estimate_disparity: expects a non-empty 8-bit BGR image");
  if (working_size > 0) net.set_working_size(working_size);
  const ImageSize work = net.input_size(bgr.rows, bgr.cols);
  cv::Mat small;
  if (work.width != bgr.cols || work.height != bgr.rows)
    small = resize_tent(bgr, {work.width, work.height});  // the training's filter (tent_resize.h)
  else
    bgr.convertTo(small, CV_32FC3);
  cv::Mat rgb;
  cv::cvtColor(small, rgb, cv::COLOR_BGR2RGB);
  rgb *= 1.0 / 255.0;  // contiguous [h][w][3] in [0, 1]
  const Tensor disparity = net.run(rgb.ptr<float>(), rgb.rows, rgb.cols, pool);
  return cv::Mat(rgb.rows, rgb.cols, CV_32FC1, const_cast<float*>(disparity.f32())).clone();
}

void set_working_size_option(DepthModel& net, int size, const char* option) {
  try {
    net.set_working_size(size);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string(option) + ": " + e.what());
  }
}

}  // namespace ampi
