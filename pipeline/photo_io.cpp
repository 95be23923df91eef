#include "pipeline/photo_io.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <vector>

#include "engine/memory_budget.h"

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

uint32_t big_endian(const std::vector<unsigned char>& b, size_t pos, int bytes) {
  uint32_t value = 0;
  for (int i = 0; i < bytes; ++i) value = value << 8 | b[pos + i];
  return value;
}

// PNG: the signature, then the IHDR chunk (length, "IHDR", width, height, ...).
std::optional<EncodedImageSize> png_size(const std::vector<unsigned char>& b) {
  if (b.size() < 24 || std::memcmp(&b[12], "IHDR", 4) != 0) return std::nullopt;
  return EncodedImageSize{big_endian(b, 16, 4), big_endian(b, 20, 4)};
}

// JPEG: walks the marker segments after SOI up to the first start-of-frame (SOF0..SOF15
// but DHT C4, JPG C8 and DAC CC, which share the range), which holds the frame's size.
std::optional<EncodedImageSize> jpeg_size(const std::vector<unsigned char>& b) {
  size_t pos = 2;
  while (pos + 1 < b.size()) {
    if (b[pos] != 0xFF) return std::nullopt;
    const unsigned char marker = b[pos + 1];
    if (marker == 0xFF) {  // fill byte before a marker
      ++pos;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {  // no length field
      pos += 2;
      continue;
    }
    if (marker == 0xD9 || marker == 0xDA || pos + 4 > b.size()) return std::nullopt;  // EOI, scan data
    const bool frame = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (!frame) {
      pos += 2 + big_endian(b, pos + 2, 2);
      continue;
    }
    // The frame header after the marker: length (2), precision (1), height (2), width (2).
    if (pos + 9 > b.size()) return std::nullopt;
    return EncodedImageSize{big_endian(b, pos + 7, 2), big_endian(b, pos + 5, 2)};
  }
  return std::nullopt;
}

// Refuses, before decoding, a PNG or JPEG whose 8-bit BGR image would not fit the budget.
void check_decoded_size(const std::string& path, const std::vector<unsigned char>& bytes) {
  const std::optional<EncodedImageSize> size = encoded_image_size(bytes);
  if (!size) return;
  check_allocation(bytes_for({uint64_t(size->width), uint64_t(size->height), 3}), path,
                   "the decoded " + std::to_string(size->width) + "x" + std::to_string(size->height) + " photo");
}

}  // namespace

std::optional<EncodedImageSize> encoded_image_size(const std::vector<unsigned char>& bytes) {
  if (starts_with(bytes, "\x89PNG\r\n\x1a\n", 8)) return png_size(bytes);
  if (starts_with(bytes, "\xFF\xD8", 2)) return jpeg_size(bytes);
  return std::nullopt;
}

void refuse_dicom(const std::string& path, const std::vector<unsigned char>& bytes) {
  constexpr size_t kDicomMagicAt = 128;
  if (bytes.size() >= kDicomMagicAt + 4 && std::memcmp(&bytes[kDicomMagicAt], "DICM", 4) == 0)
    fail(path, "DICOM files are not supported");
}

cv::Mat read_photo(const std::string& path) {
  const std::vector<unsigned char> bytes = read_file_bytes(path);
  refuse_dicom(path, bytes);
  check_not_truncated(path, bytes);
  check_decoded_size(path, bytes);
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
