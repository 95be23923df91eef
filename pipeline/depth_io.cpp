#include "pipeline/depth_io.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <vector>

#include "engine/memory_budget.h"
#include "mpi/mpi_io.h"
#include "pipeline/photo_io.h"
#include "weights_format/npy.h"

namespace ampi {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw std::runtime_error(path + ": " + problem);
}

std::vector<unsigned char> read_file_bytes(const std::string& path) {
  struct stat st;
  if (stat(path.c_str(), &st) != 0) fail(path, errno == ENOENT ? "no such file" : std::strerror(errno));
  if (S_ISDIR(st.st_mode)) fail(path, "is a directory, not a depth map");
  if (st.st_size == 0) fail(path, "empty file");
  std::ifstream in(path, std::ios::binary);
  std::vector<unsigned char> bytes(static_cast<size_t>(st.st_size));
  if (!in || !in.read(reinterpret_cast<char*>(bytes.data()), st.st_size))
    fail(path, std::string("cannot be read: ") + std::strerror(errno));
  return bytes;
}

// libpng reports a cut-off file on stderr before failing; catch it first so the user
// sees one line. A PNG ends with its IEND chunk (length, "IEND", CRC).
void check_png_complete(const std::string& path, const std::vector<unsigned char>& b) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (b.size() < 8 || std::memcmp(b.data(), kSignature, 8) != 0) return;
  if (b.size() < 20 || std::memcmp(&b[b.size() - 8], "IEND", 4) != 0) fail(path, "truncated PNG (no IEND chunk)");
}

// Refuses, before decoding, a PNG or JPEG map that would not fit the memory budget: per
// pixel up to 4 channels of 16 bits decoded plus the float map they become.
void check_decoded_size(const std::string& path, const std::vector<unsigned char>& bytes) {
  const std::optional<EncodedImageSize> size = encoded_image_size(bytes);
  if (!size) return;
  check_allocation(bytes_for({uint64_t(size->width), uint64_t(size->height), 4 * 2 + sizeof(float)}), path,
                   "the decoded " + std::to_string(size->width) + "x" + std::to_string(size->height) + " depth map");
}

cv::Mat decode_image(const std::string& path) {
  const std::vector<unsigned char> bytes = read_file_bytes(path);
  refuse_dicom(path, bytes);
  check_png_complete(path, bytes);
  check_decoded_size(path, bytes);
  cv::Mat image;
  try {
    image = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
    image.release();
  }
  if (image.empty()) fail(path, "not a readable image (unknown format or corrupt data)");
  if (image.channels() > 1) {
    std::fprintf(stderr, "ampi: note: %s has %d channels; using the first as depth\n", path.c_str(),
                 image.channels());
    cv::extractChannel(image, image, 0);
  }
  return image;
}

bool has_npy_extension(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".npy";
}

// An array of shape H x W once its size-1 axes are dropped ((1, H, W), (H, W, 1), ...).
cv::Mat read_npy_map(const std::string& path) {
  const Tensor t = read_npy(path);
  std::vector<int64_t> dims;
  for (int64_t d : t.shape())
    if (d != 1) dims.push_back(d);
  if (t.numel() == 0) fail(path, "empty array");
  while (t.rank() >= 2 && dims.size() < 2) dims.insert(dims.begin(), 1);  // 1 x 1 or 1 x N maps
  if (dims.size() != 2 || dims[0] > INT_MAX || dims[1] > INT_MAX)
    fail(path, "array of shape " + shape_str(t.shape()) + " is not a depth map (expected H x W)");
  cv::Mat map(static_cast<int>(dims[0]), static_cast<int>(dims[1]), CV_32FC1);
  std::memcpy(map.data, t.f32(), static_cast<size_t>(t.numel()) * sizeof(float));
  return map;
}

// 1/x for positive distances; zero or negative ones take the smallest disparity found.
void invert_distances(cv::Mat& map, const std::string& path) {
  float farthest = 0.0f;
  for (int y = 0; y < map.rows; ++y)
    for (const float* v = map.ptr<float>(y); v != map.ptr<float>(y) + map.cols; ++v) farthest = std::max(farthest, *v);
  if (!(farthest > 0.0f)) fail(path, "distance map has no positive value");
  const float farthest_disparity = 1.0f / farthest;
  for (int y = 0; y < map.rows; ++y) {
    float* v = map.ptr<float>(y);
    for (int x = 0; x < map.cols; ++x) {
      if (v[x] > 0.0f && !std::isfinite(1.0f / v[x])) {  // a denormal distance: 1/x overflows
        char value[32];
        std::snprintf(value, sizeof value, "%g", v[x]);
        fail(path, std::string("distance ") + value + " at (" + std::to_string(x) + ", " + std::to_string(y) +
                       ") is too small to invert");
      }
      v[x] = v[x] > 0.0f ? 1.0f / v[x] : farthest_disparity;
    }
  }
}

}  // namespace

cv::Mat read_depth_map(const std::string& path, bool is_distance) {
  cv::Mat map;
  if (has_npy_extension(path))
    map = read_npy_map(path);
  else
    decode_image(path).convertTo(map, CV_32F);
  if (!cv::checkRange(map, true)) fail(path, "contains NaN or infinite values");
  if (is_distance) invert_distances(map, path);
  return map;
}

void write_depth_png16(const cv::Mat& disparity, const std::string& path) {
  if (disparity.empty() || disparity.type() != CV_32FC1) fail(path, "disparity must be a non-empty CV_32FC1 map");
  if (!cv::checkRange(disparity, true)) fail(path, "disparity contains NaN or infinite values");
  double lo = 0, hi = 0;
  cv::minMaxLoc(disparity, &lo, &hi);
  cv::Mat png16 = cv::Mat::zeros(disparity.size(), CV_16UC1);
  if (hi > lo) disparity.convertTo(png16, CV_16U, 65535.0 / (hi - lo), -lo * 65535.0 / (hi - lo));
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", png16, bytes)) fail(path, "PNG encoding failed");
  write_file_atomic(path, bytes);
}

}  // namespace ampi
