// The adaptive multiplane image: what slicing assembles, inpainting fills, the files in
// mpi/ store and the renderer draws. Layers are ordered back to front (layer 0 is the
// farthest plane), as they are composited.
#pragma once
#include <opencv2/core.hpp>
#include <vector>

namespace ampi {

// Pinhole intrinsics of the source photo, in pixels of the layer images.
struct Camera {
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  cv::Matx33d K() const { return {fx, 0, cx, 0, fy, cy, 0, 0, 1}; }
};

// Intrinsics for an image of the given size and an assumed horizontal field of view,
// principal point at the centre. Photos carry no calibration, so the renderer assumes one.
Camera camera_from_fov(int width, int height, double horizontal_fov_degrees);

// Where slicing puts scene depth: disparity is normalised to [0, 255] (255 = nearest);
// it maps linearly to inverse depth between 1/far and 1/near.
struct DepthRange {
  double near = 1.0;
  double far = 100.0;
};
double depth_from_disparity(double disparity255, const DepthRange& range);

struct Plane {
  double depth = 1.0;         // distance z_j of the fronto-parallel plane (> 0)
  double disparity = 0.0;     // mean normalised disparity of its pixels, [0, 255]
  double disparity_lo = 0.0;  // interval [lo, hi) of normalised disparity it holds
  double disparity_hi = 0.0;  // (a plane with disparity_hi = 255 also holds 255)
  long long pixel_count = 0;  // pixels of the source disparity map the plane holds
};

struct Mpi {
  Camera camera;
  DepthRange range;
  std::vector<Plane> planes;    // back to front
  std::vector<cv::Mat> layers;  // one CV_8UC4 image per plane, BGRA (OpenCV order), straight alpha
};

}  // namespace ampi
