#include "eval/depth_eval.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "pipeline/depth_io.h"

namespace ampi {
namespace {

namespace fs = std::filesystem;

std::vector<float> values_where(const cv::Mat& map, const cv::Mat& valid) {
  std::vector<float> out;
  out.reserve(map.total());
  for (int y = 0; y < map.rows; ++y) {
    const float* v = map.ptr<float>(y);
    const uchar* m = valid.ptr<uchar>(y);
    for (int x = 0; x < map.cols; ++x)
      if (m[x]) out.push_back(v[x]);
  }
  return out;
}

// The median of an even count is the mean of the two middle values.
double median_of(std::vector<float> v) {
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  const double upper = v[mid];
  if (v.size() % 2) return upper;
  const double lower = *std::max_element(v.begin(), v.begin() + mid);
  return 0.5 * (lower + upper);
}

double std_of(const std::vector<float>& v) {
  double sum = 0, sum_sq = 0;
  for (float x : v) sum += x;
  const double mean = sum / v.size();
  for (float x : v) sum_sq += (x - mean) * (x - mean);
  return std::sqrt(sum_sq / v.size());
}

void check_inputs(const cv::Mat& prediction, const cv::Mat& reference, const cv::Mat& valid) {
  if (prediction.type() != CV_32FC1 || reference.type() != CV_32FC1 || valid.type() != CV_8UC1)
    throw std::invalid_argument("depth metrics: prediction and reference must be CV_32FC1, valid CV_8UC1");
  if (prediction.size() != reference.size() || valid.size() != reference.size())
    throw std::invalid_argument("depth metrics: prediction, reference and mask sizes differ");
  if (cv::countNonZero(valid) == 0) throw std::invalid_argument("depth metrics: no valid reference pixel");
}

}  // namespace

DepthReference read_depth_reference(const std::string& path, bool is_distance) {
  // Read raw values: the reader's own inversion would turn missing distances into the
  // farthest disparity, and they must be left out instead.
  DepthReference ref;
  ref.disparity = read_depth_map(path, false);
  ref.valid = ref.disparity > 0;
  if (cv::countNonZero(ref.valid) == 0) throw std::runtime_error(path + ": no valid (positive) reference value");
  if (is_distance) {
    cv::Mat inverse;
    cv::divide(1.0, ref.disparity, inverse);
    inverse.setTo(0, ~ref.valid);
    ref.disparity = inverse;
  }
  return ref;
}

cv::Mat align_median_std(const cv::Mat& prediction, const cv::Mat& reference, const cv::Mat& valid) {
  check_inputs(prediction, reference, valid);
  const std::vector<float> p = values_where(prediction, valid), r = values_where(reference, valid);
  const double p_std = std_of(p);
  const double scale = p_std > 0 ? std_of(r) / p_std : 0.0;
  const double p_median = median_of(p), r_median = median_of(r);
  const double floor = *std::min_element(r.begin(), r.end());
  cv::Mat aligned(prediction.size(), CV_32FC1);
  for (int y = 0; y < prediction.rows; ++y) {
    const float* in = prediction.ptr<float>(y);
    float* out = aligned.ptr<float>(y);
    for (int x = 0; x < prediction.cols; ++x)
      out[x] = static_cast<float>(std::max(floor, (in[x] - p_median) * scale + r_median));
  }
  return aligned;
}

DepthMetrics depth_metrics(const cv::Mat& prediction, const DepthReference& reference) {
  const cv::Mat aligned = align_median_std(prediction, reference.disparity, reference.valid);
  const std::vector<float> a = values_where(aligned, reference.valid);
  const std::vector<float> r = values_where(reference.disparity, reference.valid);
  double within[3] = {0, 0, 0}, sq = 0, rel = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double ratio = std::max(double(a[i]) / r[i], double(r[i]) / a[i]);
    within[0] += ratio < 1.25;
    within[1] += ratio < 1.25 * 1.25;
    within[2] += ratio < 1.25 * 1.25 * 1.25;
    const double diff = double(a[i]) - r[i];
    sq += diff * diff;
    rel += std::fabs(diff) / r[i];
  }
  const double n = double(a.size());
  return {within[0] / n, within[1] / n, within[2] / n, std::sqrt(sq / n), rel / n};
}

cv::Mat vertical_gradient_disparity(const cv::Size& size) {
  cv::Mat out(size, CV_32FC1);
  for (int y = 0; y < size.height; ++y)
    out.row(y).setTo(size.height > 1 ? double(y) / (size.height - 1) : 0.0);
  return out;
}

std::string find_depth_reference(const std::string& photo, const std::string& images_dir,
                                 const std::string& reference_dir) {
  const fs::path relative = fs::path(photo).lexically_relative(images_dir);
  const fs::path folder = fs::path(reference_dir) / relative.parent_path();
  const std::string stem = relative.stem().string();
  std::vector<std::string> found;
  std::error_code error;
  for (fs::directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
    if (!it->is_regular_file() || it->path().stem() != stem) continue;
    if (fs::equivalent(it->path(), photo, error)) continue;  // the photo itself, if the folders are one
    found.push_back(it->path().string());
  }
  if (found.empty())
    throw std::runtime_error(photo + ": no reference depth map " + (folder / stem).string() + ".* (png, npy, tif, ...)");
  if (found.size() > 1) {
    std::sort(found.begin(), found.end());
    throw std::runtime_error(photo + ": several reference depth maps (" + found[0] + ", " + found[1] +
                             "): keep one");
  }
  return found[0];
}

void DepthMetricsMean::add(const DepthMetrics& m) {
  sum_.delta1 += m.delta1;
  sum_.delta2 += m.delta2;
  sum_.delta3 += m.delta3;
  sum_.rmse += m.rmse;
  sum_.rel += m.rel;
  ++count_;
}

DepthMetrics DepthMetricsMean::mean() const {
  if (count_ == 0) return {};
  return {sum_.delta1 / count_, sum_.delta2 / count_, sum_.delta3 / count_, sum_.rmse / count_, sum_.rel / count_};
}

}  // namespace ampi
