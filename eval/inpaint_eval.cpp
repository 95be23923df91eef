#include "eval/inpaint_eval.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>

#include "inpaint/harmonic_fill.h"
#include "inpaint/push_pull.h"

namespace ampi {

cv::Mat plane_labels(const cv::Mat& disparity, const std::vector<Plane>& planes) {
  cv::Mat lut(1, kDisparityLevels, CV_8UC1);
  for (int level = 0; level < kDisparityLevels; ++level) {
    const int plane = plane_of_level(planes, level);
    if (plane < 0) throw std::invalid_argument("plane_labels: disparity level without a plane");
    lut.at<uint8_t>(level) = cv::saturate_cast<uint8_t>(plane);
  }
  cv::Mat labels;
  cv::LUT(normalize_disparity(disparity), lut, labels);
  return labels;
}

std::vector<MarginSample> margin_samples(const cv::Mat& bgr, const cv::Mat& labels, int planes,
                                         int erode_iterations, int min_removed) {
  std::vector<MarginSample> samples;
  const cv::Mat element = cv::getStructuringElement(cv::MORPH_RECT, {3, 3});
  for (int j = 0; j + 1 < planes; ++j) {
    const cv::Mat region = labels <= j;  // plane j and every plane behind it
    MarginSample s;
    s.bgr = bgr;
    // OpenCV's default erosion border leaves the photo's own edges alone, as in training
    cv::erode(region, s.known, element, {-1, -1}, erode_iterations);
    s.removed = region & ~s.known;
    if (cv::countNonZero(s.removed) >= min_removed) samples.push_back(s);
  }
  return samples;
}

double masked_psnr(const cv::Mat& filled, const cv::Mat& truth, const cv::Mat& mask) {
  cv::Mat diff;
  cv::absdiff(filled, truth, diff);
  diff.convertTo(diff, CV_32F);
  diff = diff.mul(diff);
  const double count = cv::countNonZero(mask) * double(truth.channels());
  if (count == 0) throw std::invalid_argument("masked_psnr: empty mask");
  const cv::Scalar sum = cv::sum(diff.setTo(0, mask == 0));
  const double mse = (sum[0] + sum[1] + sum[2] + sum[3]) / count;
  return mse <= 0 ? 100.0 : 10.0 * std::log10(255.0 * 255.0 / mse);  // 100 dB: identical
}

double masked_ssim(const cv::Mat& filled, const cv::Mat& truth, const cv::Mat& mask) {
  const double c1 = std::pow(0.01 * 255, 2), c2 = std::pow(0.03 * 255, 2);
  cv::Mat x, y;
  filled.convertTo(x, CV_32F);
  truth.convertTo(y, CV_32F);
  const auto blur = [](const cv::Mat& m) {
    cv::Mat out;
    cv::GaussianBlur(m, out, {11, 11}, 1.5);
    return out;
  };
  const cv::Mat mx = blur(x), my = blur(y);
  const cv::Mat sxx = blur(x.mul(x)) - mx.mul(mx), syy = blur(y.mul(y)) - my.mul(my);
  const cv::Mat sxy = blur(x.mul(y)) - mx.mul(my);
  const cv::Scalar k1 = cv::Scalar::all(c1), k2 = cv::Scalar::all(c2);  // Mat + double adds to channel 0 only
  cv::Mat num = (2 * mx.mul(my) + k1).mul(2 * sxy + k2);
  cv::Mat den = (mx.mul(mx) + my.mul(my) + k1).mul(sxx + syy + k2);
  cv::Mat ssim;
  cv::divide(num, den, ssim);
  const cv::Scalar mean = cv::mean(ssim, mask);
  double total = 0;
  for (int c = 0; c < truth.channels(); ++c) total += mean[c];
  return total / truth.channels();
}

InpaintEvaluator::InpaintEvaluator(std::vector<NamedFiller> methods) : methods_(std::move(methods)) {
  for (const NamedFiller& m : methods_) sums_.push_back({m.name});
}

void InpaintEvaluator::add(const MarginSample& sample) {
  cv::Mat visible = cv::Mat::zeros(sample.bgr.size(), CV_8UC3);
  sample.bgr.copyTo(visible, sample.known);
  for (size_t i = 0; i < methods_.size(); ++i) {
    const auto start = std::chrono::steady_clock::now();
    const cv::Mat filled = methods_[i].fill(visible, sample);
    sums_[i].seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    sums_[i].psnr += masked_psnr(filled, sample.bgr, sample.removed);
    sums_[i].ssim += masked_ssim(filled, sample.bgr, sample.removed);
    sums_[i].samples += 1;
  }
}

std::vector<MethodScore> InpaintEvaluator::scores() const {
  std::vector<MethodScore> out = sums_;
  for (MethodScore& s : out)
    if (s.samples > 0) {
      s.psnr /= s.samples;
      s.ssim /= s.samples;
    }
  return out;
}

namespace {

// cv::inpaint fills every pixel it is not shown: the removed border and the nearer
// planes' area alike (the latter is not scored). Fast marching fills the border first,
// from the known side, so the extra area does not change the scored pixels.
MarginFiller opencv_filler(double radius, int flags) {
  return [radius, flags](const cv::Mat& visible, const MarginSample& s) {
    cv::Mat filled;
    cv::inpaint(visible, ~s.known, filled, radius, flags);
    return filled;
  };
}

}  // namespace

MarginFiller telea_filler(double radius) { return opencv_filler(radius, cv::INPAINT_TELEA); }
MarginFiller navier_stokes_filler(double radius) { return opencv_filler(radius, cv::INPAINT_NS); }

MarginFiller push_pull_margin_filler() {
  return [](const cv::Mat& visible, const MarginSample& s) { return push_pull_fill(visible, s.known, s.removed); };
}

MarginFiller harmonic_margin_filler() {
  return [](const cv::Mat& visible, const MarginSample& s) { return harmonic_fill(visible, s.known, s.removed); };
}

}  // namespace ampi
