// Hand-made MPIs for the renderer tests: smooth random textures (so bilinear sampling
// differences stay small) and layers covered by random discs, all from one seed.
#pragma once
#include <opencv2/imgproc.hpp>
#include <random>

#include "mpi/mpi.h"

namespace ampi::test {

enum class Alpha {
  Binary,  // alpha is 0 or 255: compositing is exact at the identity pose
  Soft,    // disc edges fade out over a few pixels
};

inline cv::Mat smooth_texture(int width, int height, std::mt19937& rng) {
  cv::Mat noise(height, width, CV_8UC3);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int y = 0; y < height; ++y)
    for (int i = 0; i < 3 * width; ++i) noise.ptr<uint8_t>(y)[i] = static_cast<uint8_t>(byte(rng));
  cv::Mat smooth;
  cv::GaussianBlur(noise, smooth, cv::Size(0, 0), 1.5);
  // Stretch the blurred noise back to a wide range of values.
  cv::normalize(smooth, smooth, 0, 255, cv::NORM_MINMAX);
  return smooth;
}

inline cv::Mat disc_alpha(int width, int height, Alpha kind, std::mt19937& rng) {
  cv::Mat alpha(height, width, CV_8U, cv::Scalar(0));
  std::uniform_int_distribution<int> px(0, width - 1), py(0, height - 1);
  std::uniform_int_distribution<int> radius(2, std::max(3, std::min(width, height) / 4));
  for (int d = 0; d < 6; ++d) cv::circle(alpha, {px(rng), py(rng)}, radius(rng), cv::Scalar(255), cv::FILLED);
  if (kind == Alpha::Soft) cv::GaussianBlur(alpha, alpha, cv::Size(0, 0), 2.0);
  return alpha;
}

// Plane 0 (the farthest) is opaque; the others are covered by random discs. Depths go
// from `far_depth` down to `near_depth`.
inline Mpi synthetic_mpi(int width, int height, int planes, uint32_t seed, Alpha kind,
                         double near_depth = 2.0, double far_depth = 20.0) {
  std::mt19937 rng(seed);
  Mpi mpi;
  mpi.camera = camera_from_fov(width, height, 60.0);
  mpi.range = {near_depth, far_depth};
  for (int j = 0; j < planes; ++j) {
    Plane plane;
    const double t = planes == 1 ? 1.0 : static_cast<double>(j) / (planes - 1);
    plane.depth = 1.0 / ((1.0 - t) / far_depth + t / near_depth);
    mpi.planes.push_back(plane);
    cv::Mat alpha = j == 0 ? cv::Mat(height, width, CV_8U, cv::Scalar(255)) : disc_alpha(width, height, kind, rng);
    cv::Mat bgra;
    cv::Mat channels[] = {smooth_texture(width, height, rng), alpha};
    cv::merge(channels, 2, bgra);
    mpi.layers.push_back(bgra);
  }
  return mpi;
}

}  // namespace ampi::test
