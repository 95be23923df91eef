#include "pipeline/photo_io.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <vector>

namespace ampi {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw std::runtime_error(path + ": " + problem);
}

// The file as bytes, after the checks that need no decoding.
std::vector<unsigned char> read_file_bytes(const std::string& path) {
  struct stat st;
  if (stat(path.c_str(), &st) != 0)
    fail(path, errno == ENOENT ? "no such file" : std::strerror(errno));
  if (S_ISDIR(st.st_mode)) fail(path, "is a directory, not a photo");
  if (!S_ISREG(st.st_mode)) fail(path, "is not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot be read: ") + std::strerror(errno));
  if (st.st_size == 0) fail(path, "empty file");
  std::vector<unsigned char> bytes(static_cast<size_t>(st.st_size));
  if (!in.read(reinterpret_cast<char*>(bytes.data()), st.st_size))
    fail(path, "cannot be read completely");
  return bytes;
}

bool starts_with(const std::vector<unsigned char>& b, const char* magic, size_t n) {
  return b.size() >= n && std::memcmp(b.data(), magic, n) == 0;
}

// libjpeg and libpng decode what they can of a cut-off file and only warn, so a
// truncated photo would silently turn grey at the bottom: check the end markers first.
void check_not_truncated(const std::string& path, const std::vector<unsigned char>& b) {
  if (starts_with(b, "\xFF\xD8\xFF", 3)) {
    size_t end = b.size();
    while (end > 2 && (b[end - 1] == 0x00 || b[end - 1] == '\n' || b[end - 1] == '\r')) --end;
    // A well-formed JPEG ends with the end-of-image marker FF D9.
    if (end < 4 || b[end - 2] != 0xFF || b[end - 1] != 0xD9)
      fail(path, "truncated JPEG (no end-of-image marker)");
  } else if (starts_with(b, "\x89PNG\r\n\x1a\n", 8)) {
    // The last chunk of a PNG is IEND: length 0, "IEND", CRC.
    if (b.size() < 20 || std::memcmp(&b[b.size() - 8], "IEND", 4) != 0)
      fail(path, "truncated PNG (no IEND chunk)");
  }
}

}  // namespace

cv::Mat read_photo(const std::string& path) {
  const std::vector<unsigned char> bytes = read_file_bytes(path);
  check_not_truncated(path, bytes);
  cv::Mat image;
  try {
    // IMREAD_COLOR applies the EXIF orientation and converts gray, 16-bit, alpha and
    // CMYK sources to 8-bit BGR.
    image = cv::imdecode(bytes, cv::IMREAD_COLOR);
  } catch (const cv::Exception&) {
    image.release();
  }
  if (image.empty()) fail(path, "not a readable image (unknown format or corrupt data)");
  if (image.cols < kMinPhotoSide || image.rows < kMinPhotoSide)
    fail(path, "image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                   ", ampi needs at least " + std::to_string(kMinPhotoSide) + " px on each side");
  return image;
}

}  // namespace ampi
