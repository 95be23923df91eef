#include "slicing/depth_edges.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

#include "engine/thread_pool.h"
#include "slicing/adaptive.h"
#include "slicing/row_kernels.h"

namespace ampi {
namespace {

void check_inputs(const cv::Mat& bgr, const cv::Mat& disparity, const DepthEdgeParams& p) {
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw std::invalid_argument("snap_depth_edges: the photo must be a non-empty 8-bit BGR image");
  if (disparity.empty() || disparity.type() != CV_32FC1)
    throw std::invalid_argument("snap_depth_edges: the disparity map must be a non-empty CV_32FC1 image");
  if (disparity.cols > bgr.cols || disparity.rows > bgr.rows)
    throw std::invalid_argument("snap_depth_edges: the disparity map is larger than the photo");
  if (p.guide_long_side < 8) throw std::invalid_argument("snap_depth_edges: guide_long_side must be at least 8");
  if (p.radius < 0) throw std::invalid_argument("snap_depth_edges: radius must not be negative");
  if (!(p.color_sigma > 0)) throw std::invalid_argument("snap_depth_edges: color_sigma must be positive");
  if (!(p.min_step > 0)) throw std::invalid_argument("snap_depth_edges: min_step must be positive");
  if (!(p.min_growth_share > 0.5 && p.min_growth_share <= 1))
    throw std::invalid_argument("snap_depth_edges: min_growth_share must be in (0.5, 1]");
  if (!(p.ramp_margin >= 0 && p.ramp_margin < 0.5))
    throw std::invalid_argument("snap_depth_edges: ramp_margin must be in [0, 0.5)");
}

// The map and photo the fit runs on: a smaller map with the photo reduced to its size,
// or a full-size map and photo both reduced to guide_long_side.
struct FitInputs {
  cv::Mat disparity;  // CV_32FC1
  cv::Mat colour;     // CV_32FC3, 0..255
};

FitInputs fit_inputs(const cv::Mat& bgr, const cv::Mat& disparity, int guide_long_side) {
  FitInputs fit;
  cv::Size size = disparity.size();
  if (size == bgr.size() && std::max(size.width, size.height) > guide_long_side) {
    const double scale = double(guide_long_side) / std::max(size.width, size.height);
    size = {std::max(1, int(std::lround(size.width * scale))), std::max(1, int(std::lround(size.height * scale)))};
  }
  fit.disparity = disparity;
  if (size != disparity.size()) cv::resize(disparity, fit.disparity, size, 0, 0, cv::INTER_AREA);
  cv::Mat small = bgr;
  if (size != bgr.size()) cv::resize(bgr, small, size, 0, 0, cv::INTER_AREA);
  small.convertTo(fit.colour, CV_32FC3);
  return fit;
}

// The window radius at the fitting size when none is given. A map smaller than the
// photo is a network's: its ramps span a few of its own pixels, and a 64th of its long
// side (at least 2) spans them. A map of the photo's size may have been enlarged from
// any size, so its ramps may be several times wider than the pixels it has: a 32nd of
// the fitting size (16 px at 512) spans those of a map enlarged 8 times.
int default_radius(cv::Size fit, bool map_of_photo_size) {
  const int long_side = std::max(fit.width, fit.height);
  return std::max(2, map_of_photo_size ? long_side / 32 : long_side / 64);
}

// Index i of a line of n reflected at its ends as cv::BORDER_REFLECT does (fedcba|abcdef).
int reflect(int i, int n) {
  while (i < 0 || i >= n) i = i < 0 ? -i - 1 : 2 * n - i - 1;
  return i;
}

// Means over every (2 radius + 1)^2 window (borders reflected) of `channels` values per
// pixel of a height x width image whose rows `source` fills on demand (source(y, row):
// width * channels floats, interleaved). Each finished row of means goes to sink(y, row).
// Running sums: the cost does not grow with the radius, and no image of the moments is
// ever stored whole (fresh memory is what costs most here: page faults).
template <class Source, class Sink>
void box_means(int height, int width, int channels, int radius, Source source, Sink sink) {
  const size_t stride = size_t(width) * channels;
  std::vector<float> row(stride), means(stride);
  std::vector<double> column(stride, 0.0), line((width + 2 * radius) * size_t(channels)), sum(channels);
  auto add_row = [&](int y, double sign) {
    source(reflect(y, height), row.data());
    for (size_t i = 0; i < stride; ++i) column[i] += sign * row[i];
  };
  for (int y = -radius; y <= radius; ++y) add_row(y, 1.0);
  const double scale = 1.0 / double((2 * radius + 1) * (2 * radius + 1));
  for (int y = 0; y < height; ++y) {
    for (int x = -radius; x < width + radius; ++x)  // the column sums, reflected sideways
      for (int c = 0; c < channels; ++c)
        line[size_t(x + radius) * channels + c] = column[size_t(reflect(x, width)) * channels + c];
    std::fill(sum.begin(), sum.end(), 0.0);
    for (int x = 0; x < 2 * radius + 1; ++x)
      for (int c = 0; c < channels; ++c) sum[c] += line[size_t(x) * channels + c];
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < channels; ++c) {
        means[size_t(x) * channels + c] = float(sum[c] * scale);
        if (x + 1 < width) sum[c] += line[size_t(x + 2 * radius + 1) * channels + c] - line[size_t(x) * channels + c];
      }
    sink(y, means.data());
    if (y + 1 < height) {
      add_row(y + radius + 1, 1.0);
      add_row(y - radius, -1.0);
    }
  }
}

// The colour guided filter's coefficients, averaged over the windows that hold each
// pixel: planes a0, a1, a2 (per unit of blue, green, red) and b = -a . mean(colour), so
// that a . colour + b is how far a pixel's colour moves its disparity from its window's
// mean (the filter's own output adds that mean; the snapping adds the pixel's own
// disparity instead).
std::array<cv::Mat, 4> guided_coefficients(const FitInputs& fit, int radius, double eps) {
  const cv::Mat& d = fit.disparity;
  const int h = d.rows, w = d.cols;
  // Per pixel the moments the fit needs: c0 c1 c2, d, c_i d (3), c_i c_j (6, i <= j).
  constexpr int kMoments = 13;
  const int pairs[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
  auto moments = [&](int y, float* out) {
    const cv::Vec3f* c = fit.colour.ptr<cv::Vec3f>(y);
    const float* dv = d.ptr<float>(y);
    for (int x = 0; x < w; ++x, out += kMoments) {
      for (int i = 0; i < 3; ++i) out[i] = c[x][i], out[4 + i] = c[x][i] * dv[x];
      out[3] = dv[x];
      for (int k = 0; k < 6; ++k) out[7 + k] = c[x][pairs[k][0]] * c[x][pairs[k][1]];
    }
  };
  cv::Mat raw(h, w, CV_32FC4);  // a0 a1 a2 b of each window
  box_means(h, w, kMoments, radius, moments, [&](int y, const float* m) {
    cv::Vec4f* out = raw.ptr<cv::Vec4f>(y);
    for (int x = 0; x < w; ++x, m += kMoments) {
      const double mc[3] = {m[0], m[1], m[2]}, md = m[3];
      double cov[3], var[6];
      for (int i = 0; i < 3; ++i) cov[i] = m[4 + i] - mc[i] * md;
      for (int k = 0; k < 6; ++k) var[k] = m[7 + k] - mc[pairs[k][0]] * mc[pairs[k][1]];
      // (Sigma + eps I) a = cov(colour, d), solved by the adjugate (Sigma is symmetric).
      const double s00 = var[0] + eps, s01 = var[1], s02 = var[2], s11 = var[3] + eps, s12 = var[4], s22 = var[5] + eps;
      const double i00 = s11 * s22 - s12 * s12, i01 = s02 * s12 - s01 * s22, i02 = s01 * s12 - s02 * s11;
      const double i11 = s00 * s22 - s02 * s02, i12 = s01 * s02 - s00 * s12, i22 = s00 * s11 - s01 * s01;
      const double det = s00 * i00 + s01 * i01 + s02 * i02;  // > 0: Sigma + eps I is positive definite
      const double a0 = (i00 * cov[0] + i01 * cov[1] + i02 * cov[2]) / det;
      const double a1 = (i01 * cov[0] + i11 * cov[1] + i12 * cov[2]) / det;
      const double a2 = (i02 * cov[0] + i12 * cov[1] + i22 * cov[2]) / det;
      out[x] = cv::Vec4f(float(a0), float(a1), float(a2), float(-a0 * mc[0] - a1 * mc[1] - a2 * mc[2]));
    }
  });
  std::array<cv::Mat, 4> coeff;
  for (cv::Mat& m : coeff) m.create(h, w, CV_32FC1);
  box_means(h, w, 4, radius, [&](int y, float* out) { std::copy_n(raw.ptr<float>(y), 4 * w, out); },
            [&](int y, const float* m) {
              for (int k = 0; k < 4; ++k) {
                float* out = coeff[k].ptr<float>(y);
                for (int x = 0; x < w; ++x) out[x] = m[4 * x + k];
              }
            });
  return coeff;
}

// Bilinear enlargement with cv::resize's pixel-centre convention (INTER_LINEAR), one
// output row at a time and only where asked, so the enlarged planes never exist whole at
// the photo's size.
class RowEnlarger {
 public:
  RowEnlarger(cv::Size from, cv::Size to) : from_(from), to_(to), x0_(to.width), x1_(to.width), fx_(to.width) {
    for (int x = 0; x < to.width; ++x) source(x, from.width, to.width, x0_[x], x1_[x], fx_[x]);
  }
  // The two source rows of output row y and the weight of the second.
  void rows(int y, int& y0, int& y1, float& fy) const { source(y, from_.height, to_.height, y0, y1, fy); }
  // Row y of `plane` (CV_32FC1 of the `from` size) interpolated between its source rows:
  // column[0 .. from.width).
  void vertical(const cv::Mat& plane, int y, float* column) const {
    int y0, y1;
    float fy;
    rows(y, y0, y1, fy);
    const float* r0 = plane.ptr<float>(y0);
    const float* r1 = plane.ptr<float>(y1);
    for (int x = 0; x < from_.width; ++x) column[x] = r0[x] + fy * (r1[x] - r0[x]);
  }
  // Output pixels [begin, end) of that row: out[0 .. end - begin).
  void horizontal(const float* column, int begin, int end, float* out) const {
    for (int x = begin; x < end; ++x) {
      const float v0 = column[x0_[x]], v1 = column[x1_[x]];
      out[x - begin] = v0 + fx_[x] * (v1 - v0);
    }
  }
  // Whether output pixel x reads a source pixel that `flags` (a source row) marks.
  bool reads_marked(const uchar* flags, int x) const { return flags[x0_[x]] || flags[x1_[x]]; }

 private:
  static void source(int i, int from, int to, int& i0, int& i1, float& f) {
    const double s = std::clamp((i + 0.5) * from / to - 0.5, 0.0, double(from - 1));
    i0 = static_cast<int>(s);
    i1 = std::min(i0 + 1, from - 1);
    f = static_cast<float>(s - i0);
  }
  cv::Size from_, to_;
  std::vector<int> x0_, x1_;
  std::vector<float> fx_;
};

// The map extended by `pad` pixels on every side by odd reflection (d(-k) = 2 d(0) -
// d(k)), which continues a slope as the slope it is: window extremes near the border
// then see a ground plane running on, not turning back.
cv::Mat extend_slopes(const cv::Mat& d, int pad) {
  cv::Mat out;
  cv::copyMakeBorder(d, out, pad, pad, pad, pad, cv::BORDER_REFLECT_101);
  const int rows = out.rows, cols = out.cols;
  auto reflect_lines = [&](bool by_row) {
    const int n = by_row ? rows : cols;
    for (int k = 0; k < pad; ++k) {
      for (const auto& [outer, edge] : {std::pair{k, pad}, std::pair{n - 1 - k, n - 1 - pad}}) {
        cv::Mat target = by_row ? out.row(outer) : out.col(outer);
        const cv::Mat border = by_row ? out.row(edge) : out.col(edge);
        cv::Mat(2 * border - target).copyTo(target);
      }
    }
  };
  reflect_lines(true);
  reflect_lines(false);
  return out;
}

// The minimum and maximum over every (2 radius + 1)^2 window of a map extended by `pad`
// >= radius pixels (extend_slopes), cropped back to the map.
void local_extremes(const cv::Mat& extended, int pad, int radius, cv::Mat& lo, cv::Mat& hi) {
  const cv::Mat window = cv::getStructuringElement(cv::MORPH_RECT, {2 * radius + 1, 2 * radius + 1});
  const cv::Rect inner(pad, pad, extended.cols - 2 * pad, extended.rows - 2 * pad);
  cv::Mat m;
  cv::erode(extended, m, window);
  lo = m(inner).clone();
  cv::dilate(extended, m, window);
  hi = m(inner).clone();
}

// lo and hi of every window near a depth edge, lo = hi elsewhere. A slope spreads twice
// as much over a window twice as wide, a step no more: the pixels whose spread is at
// least min_step and stops growing are the cores of edges, and a window holding a core
// is near an edge (so a ramp wider than the window keeps its ends).
void edge_extremes(const cv::Mat& d, int radius, float min_step, double min_growth_share, cv::Mat& lo, cv::Mat& hi) {
  const cv::Mat extended = extend_slopes(d, 2 * radius);
  cv::Mat wide_lo, wide_hi;
  local_extremes(extended, 2 * radius, radius, lo, hi);
  local_extremes(extended, 2 * radius, 2 * radius, wide_lo, wide_hi);
  const cv::Mat spread = hi - lo;
  cv::Mat near_edge = (spread >= min_step) & (spread >= min_growth_share * (wide_hi - wide_lo));
  cv::dilate(near_edge, near_edge, cv::getStructuringElement(cv::MORPH_RECT, {2 * radius + 1, 2 * radius + 1}));
  lo.copyTo(hi, ~near_edge);
}

// Every row of the photo: where a fit pixel it is enlarged from is near an edge, the
// six fit planes (a0, a1, a2, b, lo, hi) enlarged and the row kernel run; out.disparity
// (the map enlarged) is snapped in place and out.band written.
void snap_rows(const cv::Mat& bgr, const std::array<const cv::Mat*, 6>& planes, float min_step, float margin,
               slicing::SnapRowFn snap_row, DepthEdges& out) {
  // A pixel can be near an edge only if one of the fit pixels it is enlarged from is: the
  // enlarged spread is a weighted mean of theirs. Elsewhere the map stays as enlarged.
  const cv::Mat& lo = *planes[4];
  const cv::Mat& hi = *planes[5];
  const cv::Mat edge_fit = (hi - lo) >= min_step;
  const RowEnlarger enlarger(lo.size(), bgr.size());
  const int width = bgr.cols, fit_width = lo.cols;
  default_pool().parallel_for(bgr.rows, 16, [&](int64_t begin, int64_t end) {
    // Per fit plane a vertically interpolated row; per input of the kernel a row segment.
    std::vector<float> columns(size_t(fit_width) * 6), segment(size_t(width) * 10);
    std::vector<uchar> marked(fit_width);
    float* in[10];
    for (int k = 0; k < 10; ++k) in[k] = segment.data() + size_t(width) * k;
    for (int64_t y = begin; y < end; ++y) {
      int y0, y1;
      float fy;
      enlarger.rows(int(y), y0, y1, fy);
      const uchar *e0 = edge_fit.ptr<uchar>(y0), *e1 = edge_fit.ptr<uchar>(y1);
      bool any = false;
      for (int x = 0; x < fit_width; ++x) any |= (marked[x] = e0[x] | e1[x]) != 0;
      if (!any) continue;
      for (int k = 0; k < 6; ++k) enlarger.vertical(*planes[k], int(y), columns.data() + size_t(fit_width) * k);
      float* d = out.disparity.ptr<float>(int(y));
      const cv::Vec3b* colour = bgr.ptr<cv::Vec3b>(int(y));
      for (int x = 0; x < width;) {  // each run of pixels that may be near an edge
        if (!enlarger.reads_marked(marked.data(), x)) {
          ++x;
          continue;
        }
        const int first = x;
        while (x < width && enlarger.reads_marked(marked.data(), x)) ++x;
        const int n = x - first;
        for (int k = 0; k < 6; ++k) enlarger.horizontal(columns.data() + size_t(fit_width) * k, first, x, in[k]);
        for (int i = 0; i < n; ++i) {
          for (int ch = 0; ch < 3; ++ch) in[6 + ch][i] = colour[first + i][ch];
          in[9][i] = d[first + i];
        }
        snap_row({in[9], in[6], in[7], in[8], in[0], in[1], in[2], in[3], in[4], in[5]}, n, min_step, margin,
                 d + first, out.band.ptr<uchar>(int(y)) + first);
      }
    }
  });
}

}  // namespace

cv::Mat enlarge_disparity(const cv::Mat& disparity, cv::Size size) {
  if (disparity.size() == size) return disparity;
  cv::Mat out;
  cv::resize(disparity, out, size, 0, 0, cv::INTER_LINEAR);
  return out;
}

DepthEdges snap_depth_edges(const cv::Mat& bgr, const cv::Mat& disparity, const DepthEdgeParams& p, Isa isa) {
  check_inputs(bgr, disparity, p);
  if (!cv::checkRange(disparity))
    throw std::invalid_argument("snap_depth_edges: the disparity map contains NaN or infinite values");
  const FitInputs fit = fit_inputs(bgr, disparity, p.guide_long_side);
  const int radius = p.radius > 0 ? p.radius : default_radius(fit.disparity.size(), disparity.size() == bgr.size());
  DepthEdges out;
  // Written in place below: a map of the photo's size is copied, a smaller one enlarged
  // straight into the output.
  if (disparity.size() == bgr.size())
    out.disparity = disparity.clone();
  else
    cv::resize(disparity, out.disparity, bgr.size(), 0, 0, cv::INTER_LINEAR);
  out.band = cv::Mat::zeros(bgr.size(), CV_8UC1);
  double lo_all = 0, hi_all = 0;
  cv::minMaxLoc(fit.disparity, &lo_all, &hi_all);
  if (!(hi_all > lo_all)) return out;  // a constant map has no edge

  // Colour in 0..255: the regulariser is a variance in those units.
  const double eps = std::pow(p.color_sigma * 255.0, 2);
  const std::array<cv::Mat, 4> coeff = guided_coefficients(fit, radius, eps);
  const float min_step = static_cast<float>(p.min_step / (kDisparityLevels - 1) * (hi_all - lo_all));
  cv::Mat lo, hi;
  edge_extremes(fit.disparity, radius, min_step, p.min_growth_share, lo, hi);
  snap_rows(bgr, {&coeff[0], &coeff[1], &coeff[2], &coeff[3], &lo, &hi}, min_step, static_cast<float>(p.ramp_margin),
            slicing::slicing_kernels(isa).snap_row, out);
  return out;
}

}  // namespace ampi
