// Where the new camera is, relative to the MPI's source camera.
#pragma once
#include <opencv2/core.hpp>

#include "mpi/mpi.h"

namespace ampi {

// A point X in the source camera's frame is at X_new = R X + t in the new camera's frame
// (so t = (tx, 0, 0) with tx > 0 moves the camera to the left and the scene to the
// right). `zoom` scales the new camera's focal length (dolly-zoom); the principal point
// and the image size stay those of the source camera.
struct Pose {
  cv::Matx33d R = cv::Matx33d::eye();
  cv::Vec3d t{0, 0, 0};
  double zoom = 1.0;
};

// Rotation about the camera's x, y and z axes by these angles (degrees), applied in that
// order: R = Rz * Ry * Rx.
cv::Matx33d rotation_from_degrees(const cv::Vec3d& angles);

// H = K_new (R + t n^T / depth) K^-1 with n = (0, 0, 1): maps pixels of the
// fronto-parallel plane at `depth` in the source image to pixels of the new view
// (pixel centres at integer coordinates).
cv::Matx33d plane_homography(const Camera& camera, const Pose& pose, double depth);

}  // namespace ampi
