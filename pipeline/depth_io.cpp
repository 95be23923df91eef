#include "pipeline/depth_io.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <vector>

#include "mpi/mpi_io.h"

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

cv::Mat decode_image(const std::string& path) {
  const std::vector<unsigned char> bytes = read_file_bytes(path);
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

// 1/x for positive distances; zero or negative ones take the smallest disparity found.
void invert_distances(cv::Mat& map, const std::string& path) {
  float farthest = 0.0f;
  for (int y = 0; y < map.rows; ++y)
    for (const float* v = map.ptr<float>(y); v != map.ptr<float>(y) + map.cols; ++v) farthest = std::max(farthest, *v);
  if (!(farthest > 0.0f)) fail(path, "distance map has no positive value");
  const float farthest_disparity = 1.0f / farthest;
  for (int y = 0; y < map.rows; ++y) {
    float* v = map.ptr<float>(y);
    for (int x = 0; x < map.cols; ++x) v[x] = v[x] > 0.0f ? 1.0f / v[x] : farthest_disparity;
  }
}

}  // namespace

cv::Mat read_depth_map(const std::string& path, bool is_distance) {
  const cv::Mat raw = decode_image(path);
  cv::Mat map;
  raw.convertTo(map, CV_32F);
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
