// User-supplied depth maps in, 16-bit disparity PNGs out. ampi works on disparity
// (relative inverse depth, larger = nearer); a map of distances is inverted on import.
#pragma once
#include <opencv2/core.hpp>
#include <string>

namespace ampi {

// Reads a depth map as CV_32FC1 disparity (larger = nearer). Accepts any one-channel
// image OpenCV decodes unchanged (8/16-bit PNG, float TIFF, ...) and .npy arrays of
// numbers (weights_format/npy.h) of rank 2 or more whose shape is H x W once size-1
// axes are dropped. A multi-channel image is read from its first channel, with a note
// on stderr. is_distance: the values are distances and become 1/x; zero or negative
// distances (no measurement) get the farthest measured distance's disparity. Throws
// std::runtime_error "PATH: problem" for a missing, empty or unreadable file, a wrong
// rank or shape, NaN or infinite values, or a distance map without a positive value.
cv::Mat read_depth_map(const std::string& path, bool is_distance);

// Writes disparity (CV_32FC1, finite) as a 16-bit PNG normalised to 0..65535 (larger =
// nearer; a constant map is all 0), atomically (PATH.tmp, then a rename). Throws
// std::runtime_error "PATH: problem".
void write_depth_png16(const cv::Mat& disparity, const std::string& path);

}  // namespace ampi
