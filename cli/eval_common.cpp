#include "cli/eval_common.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace ampi::cli {

namespace fs = std::filesystem;

std::vector<std::string> list_images(const std::string& dir) {
  if (!fs::is_directory(dir)) throw std::runtime_error(dir + ": not a directory");
  std::vector<std::string> found;
  // Linked folders are followed: training/archive_photos.py's photo root links ../shared's.
  for (const auto& entry : fs::recursive_directory_iterator(dir, fs::directory_options::follow_directory_symlink)) {
    if (!entry.is_regular_file()) continue;
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext == ".jpg" || ext == ".jpeg" || ext == ".png") found.push_back(entry.path().string());
  }
  if (found.empty()) throw std::runtime_error(dir + ": no .jpg, .jpeg or .png photos");
  std::sort(found.begin(), found.end());
  return found;
}

cv::Mat fit_long_side(const cv::Mat& bgr, int max_side) {
  const double scale = double(max_side) / std::max(bgr.cols, bgr.rows);
  if (scale >= 1) return bgr;
  cv::Mat out;
  cv::resize(bgr, out, {}, scale, scale, cv::INTER_AREA);
  return out;
}

}  // namespace ampi::cli
