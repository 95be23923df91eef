#include "inpaint/net_filler.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "inpaint/harmonic_fill.h"
#include "inpaint/push_pull.h"

namespace ampi {

namespace {

int round_up(int v, int m) { return (v + m - 1) / m * m; }

// Grows [lo, lo + len) to a multiple of m inside [0, limit): to the right first, then to
// the left. Returns the padded length (>= the grown one when limit is too small).
int fit_span(int& lo, int& len, int limit, int m) {
  const int want = round_up(len, m);
  const int right = std::min(want - len, limit - (lo + len));
  len += right;
  const int left = std::min(want - len, lo);
  lo -= left;
  len += left;
  return want;
}

// The window's network input: rgb in [-1, 1] and hole (1 where not known or padding).
void window_input(const cv::Mat& image, const cv::Mat& known, const cv::Rect& win, int ph, int pw,
                  std::vector<float>& rgb, std::vector<float>& hole) {
  rgb.assign(size_t(ph) * pw * 3, 0.0f);
  hole.assign(size_t(ph) * pw, 1.0f);
  for (int y = 0; y < win.height; ++y) {
    const cv::Vec4b* px = image.ptr<cv::Vec4b>(win.y + y) + win.x;
    const uint8_t* kn = known.ptr<uint8_t>(win.y + y) + win.x;
    for (int x = 0; x < win.width; ++x) {
      const size_t p = size_t(y) * pw + x;
      for (int c = 0; c < 3; ++c) rgb[p * 3 + c] = px[x][2 - c] / 127.5f - 1.0f;  // BGR -> RGB
      hole[p] = kn[x] ? 0.0f : 1.0f;
    }
  }
}

uint8_t to_byte(float v) { return cv::saturate_cast<uint8_t>(std::lround((v + 1.0f) * 127.5f)); }

void fill_core(const InpaintNet& net, const cv::Mat& image, const cv::Mat& known,
               const cv::Mat& fill, const cv::Rect& core, int halo, cv::Mat& result,
               ThreadPool& pool) {
  cv::Rect win = cv::Rect(core.x - halo, core.y - halo, core.width + 2 * halo, core.height + 2 * halo) &
                 cv::Rect(0, 0, image.cols, image.rows);
  const int m = net.multiple();
  const int pw = fit_span(win.x, win.width, image.cols, m);
  const int ph = fit_span(win.y, win.height, image.rows, m);
  std::vector<float> rgb, hole, out(size_t(ph) * pw * 3);
  window_input(image, known, win, ph, pw, rgb, hole);
  net.run(rgb.data(), hole.data(), ph, pw, out.data(), pool);
  for (int y = core.y; y < core.y + core.height; ++y) {
    const uint8_t* f = fill.ptr<uint8_t>(y);
    cv::Vec4b* dst = result.ptr<cv::Vec4b>(y);
    for (int x = core.x; x < core.x + core.width; ++x) {
      if (!f[x]) continue;
      const float* o = &out[(size_t(y - win.y) * pw + (x - win.x)) * 3];
      for (int c = 0; c < 3; ++c) dst[x][2 - c] = to_byte(o[c]);
    }
  }
}

// The network's input colour: its prefill in every unknown pixel.
cv::Mat prefilled(Prefill prefill, const cv::Mat& image, const cv::Mat& known, ThreadPool& pool) {
  switch (prefill) {
    case Prefill::PushPull: return push_pull_fill(image, known, known == 0);
    case Prefill::Harmonic: return harmonic_fill(image, known, known == 0, {}, pool);
    case Prefill::None: break;
  }
  return image;
}

}  // namespace

cv::Mat inpaint_layer(const InpaintNet& net, const cv::Mat& image, const cv::Mat& known,
                      const cv::Mat& fill, const InpaintTiling& tiling, ThreadPool& pool) {
  if (image.type() != CV_8UC4 || known.type() != CV_8UC1 || fill.type() != CV_8UC1 ||
      known.size() != image.size() || fill.size() != image.size())
    throw std::invalid_argument("inpaint_layer: needs a CV_8UC4 image and CV_8UC1 masks of its size");
  if (tiling.core < net.multiple() || tiling.halo < 0)
    throw std::invalid_argument("inpaint_layer: tile core must be at least the net's multiple, halo >= 0");
  cv::Mat result = image.clone();
  std::vector<cv::Point> points;
  cv::findNonZero(fill, points);
  if (points.empty()) return result;
  const cv::Mat source = prefilled(net.prefill(), image, known, pool);
  const cv::Rect box = cv::boundingRect(points);
  for (int y = box.y; y < box.br().y; y += tiling.core)
    for (int x = box.x; x < box.br().x; x += tiling.core) {
      const cv::Rect cell = cv::Rect(x, y, tiling.core, tiling.core) & box;
      std::vector<cv::Point> in_cell;
      cv::findNonZero(fill(cell), in_cell);
      if (in_cell.empty()) continue;
      // run on the fill's own box within the cell: sparse cells cost a small window
      const cv::Rect core = cv::boundingRect(in_cell) + cell.tl();
      fill_core(net, source, known, fill, core, tiling.halo, result, pool);
    }
  return result;
}

LayerFiller inpaint_net_filler(std::shared_ptr<const InpaintNet> net, InpaintTiling tiling) {
  if (!net) throw std::invalid_argument("inpaint_net_filler: no network");
  return [net, tiling](const cv::Mat& image, const cv::Mat& known, const cv::Mat& fill) {
    return inpaint_layer(*net, image, known, fill, tiling);
  };
}

}  // namespace ampi
