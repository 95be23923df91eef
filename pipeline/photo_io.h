// Decoding the user's photo: every way a file can fail to be a usable photo ends here
// as one line naming the file and the problem.
#pragma once
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

namespace ampi {

// Smallest side ampi accepts: below it the depth network sees less than one 16x16 block.
constexpr int kMinPhotoSide = 16;

// Width and height from a PNG's IHDR chunk or a JPEG's start-of-frame marker: what the
// image will decode to, known before the decoder allocates it (OpenCV 4.6 has no public
// header-only reader). Empty for other formats and for headers too short to tell.
// (A PNG header may claim up to 2^32 - 1 pixels a side, more than an int holds.)
struct EncodedImageSize {
  int64_t width = 0, height = 0;
};
std::optional<EncodedImageSize> encoded_image_size(const std::vector<unsigned char>& bytes);

// Throws std::runtime_error "PATH: DICOM files are not supported" for bytes OpenCV would
// hand to its DICOM decoder ("DICM" at byte 128): GDCM aborts the whole process on some
// malformed DICOM files (fuzz_depth_map found one), and no photo or depth map is one.
void refuse_dicom(const std::string& path, const std::vector<unsigned char>& bytes);

// Reads a photo as 8-bit BGR with its EXIF orientation applied. Grayscale, 16-bit,
// alpha (dropped) and CMYK inputs are converted. Throws std::runtime_error
// "PATH: problem" for a missing path, a directory, an unreadable, empty, truncated or
// unrecognised file, or an image smaller than kMinPhotoSide; a PNG or JPEG whose decoded
// size would exceed the memory budget (engine/memory_budget.h) is refused before it is
// decoded.
cv::Mat read_photo(const std::string& path);

}  // namespace ampi
