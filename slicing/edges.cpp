#include "slicing/edges.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <vector>

#include "engine/thread_pool.h"

namespace ampi {
namespace {

// The pixel states of the edge map, as OpenCV's Canny keeps them.
enum : uint8_t { kCandidate = 0, kNotEdge = 1, kEdge = 2 };

// tan(22.5 degrees) in 15-bit fixed point: the direction test of OpenCV's Canny.
constexpr int kShift = 15;
constexpr int kTan22 = 13573;  // round(0.41421356 * 2^15)

// Sobel gradients and their L1 magnitude for one row of the image (replicated borders:
// `padded` has one extra pixel on every side). mag has one zero column on each side. All
// fit 16 bits (|dx|, |dy| <= 1020), and the loop is written so the compiler vectorises it.
void gradient_row(const cv::Mat& padded, int y, int16_t* __restrict dx, int16_t* __restrict dy,
                  int16_t* __restrict mag) {
  const int w = padded.cols - 2;
  const uint8_t* __restrict above = padded.ptr<uint8_t>(y);  // padded row y is image row y - 1
  const uint8_t* __restrict here = padded.ptr<uint8_t>(y + 1);
  const uint8_t* __restrict below = padded.ptr<uint8_t>(y + 2);
  for (int x = 0; x < w; ++x) {  // padded column x + 1 is image column x
    const int16_t gx = static_cast<int16_t>((above[x + 2] + 2 * here[x + 2] + below[x + 2]) -
                                            (above[x] + 2 * here[x] + below[x]));
    const int16_t gy = static_cast<int16_t>((below[x] + 2 * below[x + 1] + below[x + 2]) -
                                            (above[x] + 2 * above[x + 1] + above[x + 2]));
    dx[x] = gx;
    dy[x] = gy;
    mag[x + 1] = static_cast<int16_t>((gx < 0 ? -gx : gx) + (gy < 0 ? -gy : gy));
  }
  mag[0] = mag[w + 1] = 0;
}

// Whether a pixel of magnitude m is a local maximum across its edge: along the gradient's
// direction, quantised to horizontal, vertical or one of the diagonals. One side compares
// strictly, the other not, so a plateau keeps exactly one pixel (OpenCV's choice).
bool local_max(int m, int gx, int gy, const int16_t* prev, const int16_t* cur, const int16_t* next, int j) {
  const int x = std::abs(gx), y = std::abs(gy) << kShift;
  const int tg22x = x * kTan22;
  if (y < tg22x) return m > cur[j - 1] && m >= cur[j + 1];
  const int tg67x = tg22x + (x << (kShift + 1));
  if (y > tg67x) return m > prev[j] && m >= next[j];
  const int s = (gx ^ gy) < 0 ? -1 : 1;
  return m > prev[j - s] && m > next[j + s];
}

// Non-maximum suppression of image rows [begin, end): marks the map's local maxima above
// `low` as candidates, those above `high` as edges (pushed on `strong`). Keeps three rows
// of magnitudes (rows outside the image count 0) and two of gradients.
void suppress_rows(const cv::Mat& padded, int low, int high, int begin, int end, uint8_t* map,
                   std::vector<uint8_t*>& strong) {
  const int w = padded.cols - 2, h = padded.rows - 2, map_step = w + 2;
  std::vector<int16_t> mags(3 * static_cast<size_t>(map_step), 0);
  std::vector<int16_t> grads(4 * static_cast<size_t>(w));
  int16_t* mag[3] = {&mags[0], &mags[map_step], &mags[2 * map_step]};  // prev, cur, next
  int16_t* dx[2] = {&grads[0], &grads[2 * w]};                         // cur, next
  int16_t* dy[2] = {&grads[w], &grads[3 * w]};
  if (begin > 0) gradient_row(padded, begin - 1, dx[1], dy[1], mag[1]);  // becomes prev
  gradient_row(padded, begin, dx[1], dy[1], mag[2]);
  for (int y = begin; y < end; ++y) {
    std::swap(mag[0], mag[1]);
    std::swap(mag[1], mag[2]);
    std::swap(dx[0], dx[1]);
    std::swap(dy[0], dy[1]);
    if (y + 1 < h)
      gradient_row(padded, y + 1, dx[1], dy[1], mag[2]);
    else
      std::fill(mag[2], mag[2] + map_step, 0);
    uint8_t* row = map + static_cast<size_t>(y + 1) * map_step + 1;
    for (int x = 0; x < w; ++x) {
      const int m = mag[1][x + 1];
      if (m <= low || !local_max(m, dx[0][x], dy[0][x], mag[0], mag[1], mag[2], x + 1)) continue;
      row[x] = m > high ? kEdge : kCandidate;
      if (m > high) strong.push_back(row + x);
    }
  }
}

}  // namespace

cv::Mat canny_edges(const cv::Mat& levels, double low_threshold, double high_threshold) {
  CV_Assert(levels.type() == CV_8UC1 && !levels.empty());
  if (!(low_threshold >= 0 && high_threshold >= low_threshold))
    throw std::invalid_argument("Canny thresholds must satisfy 0 <= low <= high");
  const int low = static_cast<int>(std::floor(low_threshold));
  const int high = static_cast<int>(std::floor(high_threshold));
  const int w = levels.cols, h = levels.rows, map_step = w + 2;
  cv::Mat padded;
  cv::copyMakeBorder(levels, padded, 1, 1, 1, 1, cv::BORDER_REPLICATE);
  // The edge map with a border of kNotEdge. Blocks of rows are suppressed in parallel
  // (each writes only its own rows); hysteresis then follows edges across them.
  std::vector<uint8_t> map(static_cast<size_t>(map_step) * (h + 2), kNotEdge);
  constexpr int kBlockRows = 32;
  const int blocks = (h + kBlockRows - 1) / kBlockRows;
  std::vector<std::vector<uint8_t*>> strong(blocks);
  default_pool().parallel_for(blocks, 1, [&](int64_t first, int64_t last) {
    for (int64_t b = first; b < last; ++b)
      suppress_rows(padded, low, high, static_cast<int>(b) * kBlockRows,
                    std::min(h, static_cast<int>(b + 1) * kBlockRows), map.data(), strong[b]);
  });
  std::vector<uint8_t*> stack;
  for (const auto& s : strong) stack.insert(stack.end(), s.begin(), s.end());
  // Hysteresis: candidates 8-connected to an edge become edges.
  const std::ptrdiff_t neighbours[8] = {-map_step - 1, -map_step, -map_step + 1, -1, 1,
                                        map_step - 1,  map_step,  map_step + 1};
  while (!stack.empty()) {
    uint8_t* p = stack.back();
    stack.pop_back();
    for (std::ptrdiff_t d : neighbours)
      if (p[d] == kCandidate) {
        p[d] = kEdge;
        stack.push_back(p + d);
      }
  }
  cv::Mat edges(levels.size(), CV_8UC1);
  for (int y = 0; y < h; ++y) {
    const uint8_t* row = &map[static_cast<size_t>(y + 1) * map_step + 1];
    uint8_t* out = edges.ptr<uint8_t>(y);
    for (int x = 0; x < w; ++x) out[x] = row[x] == kEdge ? 255 : 0;
  }
  return edges;
}

namespace {

// row_any[x] = whether row[x - anchor .. x - anchor + size - 1] (clipped to the row)
// holds a nonzero pixel: a count of them slides along the row.
void any_in_row_window(const uint8_t* row, int w, int size, int anchor, uint8_t* row_any) {
  int count = 0;
  for (int x = 0; x < std::min(w, size - 1 - anchor); ++x) count += row[x] != 0;
  for (int x = 0; x < w; ++x) {
    const int enter = x - anchor + size - 1, leave = x - anchor - 1;
    if (enter < w) count += row[enter] != 0;
    if (leave >= 0) count -= row[leave] != 0;
    row_any[x] = count > 0;
  }
}

}  // namespace

cv::Mat widen_edges(const cv::Mat& mask, int size) {
  CV_Assert(mask.type() == CV_8UC1 && !mask.empty() && size >= 1);
  const int w = mask.cols, h = mask.rows, anchor = size / 2;
  // Rows' window results for the rows in the vertical window (a ring of `size` rows),
  // and per column how many of them are set.
  std::vector<uint8_t> ring(static_cast<size_t>(size) * w);
  std::vector<int> count(w, 0);
  auto row_any = [&](int r) { return &ring[static_cast<size_t>(r % size) * w]; };
  auto enter = [&](int r) {
    any_in_row_window(mask.ptr<uint8_t>(r), w, size, anchor, row_any(r));
    for (int x = 0; x < w; ++x) count[x] += row_any(r)[x];
  };
  for (int r = 0; r < std::min(h, size - 1 - anchor); ++r) enter(r);
  cv::Mat band(mask.size(), CV_8UC1);
  for (int y = 0; y < h; ++y) {  // window rows [y - anchor, y - anchor + size - 1]
    if (y - anchor + size - 1 < h) enter(y - anchor + size - 1);
    uint8_t* out = band.ptr<uint8_t>(y);
    for (int x = 0; x < w; ++x) out[x] = count[x] > 0 ? 255 : 0;
    const int leave = y - anchor;  // not in the next row's window
    if (leave >= 0)
      for (int x = 0; x < w; ++x) count[x] -= row_any(leave)[x];
  }
  return band;
}

}  // namespace ampi
