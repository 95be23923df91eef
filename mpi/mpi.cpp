#include "mpi/mpi.h"

#include <cmath>
#include <stdexcept>

namespace ampi {

Camera camera_from_fov(int width, int height, double horizontal_fov_degrees) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("camera: image size must be positive");
  if (!(horizontal_fov_degrees > 0 && horizontal_fov_degrees < 180))
    throw std::invalid_argument("camera: field of view must be in (0, 180) degrees");
  Camera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = 0.5 * width / std::tan(0.5 * horizontal_fov_degrees * M_PI / 180.0);
  c.cx = 0.5 * width;
  c.cy = 0.5 * height;
  return c;
}

double depth_from_disparity(double disparity255, const DepthRange& range) {
  const double t = disparity255 / 255.0;
  return 1.0 / (t / range.near + (1.0 - t) / range.far);
}

}  // namespace ampi
