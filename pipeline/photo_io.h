// Decoding the user's photo: every way a file can fail to be a usable photo ends here
// as one line naming the file and the problem.
#pragma once
#include <opencv2/core.hpp>
#include <string>

namespace ampi {

// Smallest side ampi accepts: below it the depth network sees less than one 16x16 block.
constexpr int kMinPhotoSide = 16;

// Reads a photo as 8-bit BGR with its EXIF orientation applied. Grayscale, 16-bit,
// alpha (dropped) and CMYK inputs are converted. Throws std::runtime_error
// "PATH: problem" for a missing path, a directory, an unreadable, empty, truncated or
// unrecognised file, or an image smaller than kMinPhotoSide.
cv::Mat read_photo(const std::string& path);

}  // namespace ampi
