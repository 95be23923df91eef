#include "pipeline/tent_resize.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <opencv2/core/utility.hpp>

namespace ampi {
namespace {

// The input samples [first, first + weights.size()) one output sample averages.
struct Taps {
  int first = 0;
  std::vector<float> weights;
};

std::vector<Taps> tent_taps(int in, int out) {
  const double factor = double(in) / out, half_width = std::max(factor, 1.0);
  std::vector<Taps> taps(out);
  for (int i = 0; i < out; ++i) {
    const double centre = (i + 0.5) * factor;
    const int first = std::max(0, int(std::floor(centre - half_width)));
    const int end = std::min(in, int(std::ceil(centre + half_width)) + 1);
    std::vector<double> w;
    for (int j = first; j < end; ++j) w.push_back(std::max(0.0, 1.0 - std::abs(j + 0.5 - centre) / half_width));
    double sum = 0;
    for (double v : w) sum += v;
    taps[i].first = first;
    for (double v : w) taps[i].weights.push_back(float(v / sum));
  }
  return taps;
}

// Each row of dst the weighted sum of rows of src (T samples) along y: first, so that
// the long inner loop runs over whole contiguous rows and vectorises.
template <class T>
void filter_columns(const cv::Mat& src, const std::vector<Taps>& taps, cv::Mat& dst) {
  const int values = src.cols * src.channels();
  cv::parallel_for_(cv::Range(0, dst.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      float* out = dst.ptr<float>(y);
      std::fill(out, out + values, 0.0f);
      const Taps& t = taps[y];
      for (size_t k = 0; k < t.weights.size(); ++k) {
        const T* in = src.ptr<T>(t.first + int(k));
        const float w = t.weights[k];
        for (int v = 0; v < values; ++v) out[v] += w * float(in[v]);
      }
    }
  });
}

// Each row of src (floats, `channels` interleaved) filtered along x into dst's row.
void filter_rows(const cv::Mat& src, const std::vector<Taps>& taps, int channels, cv::Mat& dst) {
  cv::parallel_for_(cv::Range(0, src.rows), [&](const cv::Range& rows) {
    std::vector<float> sum(channels);
    for (int y = rows.start; y < rows.end; ++y) {
      const float* in = src.ptr<float>(y);
      float* out = dst.ptr<float>(y);
      for (const Taps& t : taps) {
        std::fill(sum.begin(), sum.end(), 0.0f);
        const float* p = in + size_t(t.first) * channels;
        for (float w : t.weights)
          for (int c = 0; c < channels; ++c) sum[c] += w * *p++;
        out = std::copy(sum.begin(), sum.end(), out);
      }
    }
  });
}

}  // namespace

cv::Mat resize_tent(const cv::Mat& src, cv::Size size) {
  if (src.empty() || (src.depth() != CV_8U && src.depth() != CV_32F))
    throw std::invalid_argument("resize_tent: expects a non-empty 8-bit or float image");
  if (size.width <= 0 || size.height <= 0) throw std::invalid_argument("resize_tent: sizes must be positive");
  const int channels = src.channels();
  cv::Mat down(size.height, src.cols, CV_32FC(channels));
  const std::vector<Taps> y_taps = tent_taps(src.rows, size.height);
  if (src.depth() == CV_8U)
    filter_columns<uchar>(src, y_taps, down);
  else
    filter_columns<float>(src, y_taps, down);
  cv::Mat out(size, CV_32FC(channels));
  filter_rows(down, tent_taps(src.cols, size.width), channels, out);
  return out;
}

}  // namespace ampi
