// The written MPI of a photo larger than MpiOptions::max_working_side: the MPI is made
// at the reduced size, and its layers are brought back to the photo's full resolution
// only as they are written, one at a time, so memory does not grow with eight
// photo-sized layers (at 8K, 1 GB of layers and the fillers' pyramids over them).
//
// A full-resolution layer holds, opaque and in the photo's own colours, every photo pixel
// whose disparity (the reduced map, enlarged) falls in the plane's interval; elsewhere it
// is the reduced layer enlarged (nearest neighbour): the inpainted margins, transparent
// where the reduced layer is.
#pragma once
#include <opencv2/core.hpp>
#include <string>

#include "pipeline/make_mpi.h"

namespace ampi {

// Whether `result` was made at a reduced size (its MPI is not at the photo's size).
inline bool is_reduced(const MpiResult& result) { return !result.full_bgr.empty(); }

// The full-resolution layer of `plane`: bgr the photo (CV_8UC3), levels its normalised
// disparity (CV_8UC1, the photo's size), reduced_layer the plane's layer of the reduced
// MPI (CV_8UC4).
cv::Mat full_resolution_layer(const cv::Mat& bgr, const cv::Mat& levels, const Plane& plane,
                              const cv::Mat& reduced_layer);

// Writes the MPI folder (mpi_io.h) at the photo's size: write_mpi itself unless the
// result is reduced.
void write_mpi_at_photo_size(const MpiResult& result, const std::string& dir);

// The disparity at the photo's size (enlarged when the result is reduced).
cv::Mat disparity_at_photo_size(const MpiResult& result);

}  // namespace ampi
