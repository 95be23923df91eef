#include "render/pose.h"

#include <cmath>

namespace ampi {

cv::Matx33d rotation_from_degrees(const cv::Vec3d& angles) {
  const double ax = angles[0] * M_PI / 180.0, ay = angles[1] * M_PI / 180.0,
               az = angles[2] * M_PI / 180.0;
  const cv::Matx33d rx(1, 0, 0, 0, std::cos(ax), -std::sin(ax), 0, std::sin(ax), std::cos(ax));
  const cv::Matx33d ry(std::cos(ay), 0, std::sin(ay), 0, 1, 0, -std::sin(ay), 0, std::cos(ay));
  const cv::Matx33d rz(std::cos(az), -std::sin(az), 0, std::sin(az), std::cos(az), 0, 0, 0, 1);
  return rz * ry * rx;
}

cv::Matx33d plane_homography(const Camera& camera, const Pose& pose, double depth) {
  cv::Matx33d motion = pose.R;  // R + t n^T / depth: t / depth added to the third column
  for (int r = 0; r < 3; ++r) motion(r, 2) += pose.t[r] / depth;
  const cv::Matx33d k = camera.K();
  const cv::Matx33d k_new(camera.fx * pose.zoom, 0, camera.cx, 0, camera.fy * pose.zoom, camera.cy, 0, 0, 1);
  return k_new * motion * k.inv();
}

}  // namespace ampi
