#include "pipeline/full_resolution.h"

#include <opencv2/imgproc.hpp>

#include "mpi/mpi_io.h"
#include "slicing/adaptive.h"

namespace ampi {

cv::Mat full_resolution_layer(const cv::Mat& bgr, const cv::Mat& levels, const Plane& plane,
                              const cv::Mat& reduced_layer) {
  CV_Assert(bgr.type() == CV_8UC3 && levels.type() == CV_8UC1 && levels.size() == bgr.size() &&
            reduced_layer.type() == CV_8UC4);
  cv::Mat layer;
  cv::resize(reduced_layer, layer, bgr.size(), 0, 0, cv::INTER_NEAREST);
  const int lo = static_cast<int>(plane.disparity_lo);
  const int end = interval_end(static_cast<int>(plane.disparity_hi));
  for (int y = 0; y < bgr.rows; ++y) {
    const uchar* level = levels.ptr<uchar>(y);
    const cv::Vec3b* colour = bgr.ptr<cv::Vec3b>(y);
    cv::Vec4b* out = layer.ptr<cv::Vec4b>(y);
    for (int x = 0; x < bgr.cols; ++x)
      if (level[x] >= lo && level[x] < end) out[x] = {colour[x][0], colour[x][1], colour[x][2], 255};
  }
  return layer;
}

cv::Mat disparity_at_photo_size(const MpiResult& result) {
  if (!is_reduced(result)) return result.disparity;
  cv::Mat enlarged;
  cv::resize(result.disparity, enlarged, result.full_bgr.size(), 0, 0, cv::INTER_LINEAR);
  return enlarged;
}

void write_mpi_at_photo_size(const MpiResult& result, const std::string& dir) {
  if (!is_reduced(result)) return write_mpi(result.mpi, dir);
  // Levels of the enlarged map by the reduced map's range, the one its planes were cut in
  // (enlarging can only narrow the range).
  double lo = 0, hi = 0;
  cv::minMaxLoc(result.disparity, &lo, &hi);
  cv::Mat levels(result.full_bgr.size(), CV_8UC1, cv::Scalar(0));
  if (hi > lo) {
    const double scale = (kDisparityLevels - 1) / (hi - lo);
    disparity_at_photo_size(result).convertTo(levels, CV_8U, scale, -lo * scale);
  }
  Mpi description;
  description.camera = result.full_camera;
  description.range = result.mpi.range;
  description.planes = result.mpi.planes;
  write_mpi_streamed(
      description,
      [&](size_t j) {
        return full_resolution_layer(result.full_bgr, levels, result.mpi.planes[j], result.mpi.layers[j]);
      },
      dir);
}

}  // namespace ampi
