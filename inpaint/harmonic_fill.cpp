#include "inpaint/harmonic_fill.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

#include "inpaint/push_pull.h"

namespace ampi {
namespace {

// Iterations run together in one pass over the rows (see relax_plane): 8 keep a window of
// 32 rows in cache, where one pass per half-sweep streams the whole image from memory.
constexpr int kFusedIterations = 8;
// A coarse cell at least this much known is kept as known. Half keeps the boundary where
// it is at every level; counting only wholly known cells moved it into the known side by
// up to a coarse cell and cost 0.09 dB in `ampi eval inpaint` (10 photos, coarsest 128).
constexpr float kKnownShare = 0.5f;

// Runs of moving pixels closer than this are swept as one: computing a few fixed
// pixels' steps (then multiplied by 0) costs less than starting another vector loop.
constexpr int kRunGap = 16;

// Which pixels each half-sweep updates: the moving (unknown) ones of one colour
// ((x + y) & 1) as 0/1 per pixel, and per row the runs [start, end) of moving pixels of
// either colour, so rows crossing a hole's fixed interior skip it.
struct Unknowns {
  cv::Mat selected[2];  // CV_8UC1 0 or 1: a step times it is exactly nothing or the step
  std::vector<std::vector<cv::Range>> runs;
};

Unknowns unknown_pixels(const cv::Mat& known) {
  Unknowns u;
  for (cv::Mat& s : u.selected) s = cv::Mat::zeros(known.size(), CV_8UC1);
  u.runs.resize(known.rows);
  for (int y = 0; y < known.rows; ++y) {
    const uint8_t* k = known.ptr<uint8_t>(y);
    std::vector<cv::Range>& runs = u.runs[y];
    for (int x = 0; x < known.cols; ++x) {
      if (k[x]) continue;
      u.selected[(x + y) & 1].ptr<uint8_t>(y)[x] = 1;
      if (!runs.empty() && x - runs.back().end < kRunGap)
        runs.back().end = x + 1;
      else
        runs.emplace_back(x, x + 1);
    }
  }
  return u;
}

// One pixel anywhere: v += omega (mean of the neighbours inside the image - v). The
// neighbours are summed left, right, up, down, as the numpy version does, so both round
// alike.
void relax_pixel(cv::Mat& f, int y, int x, float omega) {
  float* row = f.ptr<float>(y);
  float sum = 0.0f, n = 0.0f;
  if (x > 0) sum += row[x - 1], n += 1;
  if (x + 1 < f.cols) sum += row[x + 1], n += 1;
  if (y > 0) sum += f.ptr<float>(y - 1)[x], n += 1;
  if (y + 1 < f.rows) sum += f.ptr<float>(y + 1)[x], n += 1;
  if (n > 0) row[x] += omega * (sum / n - row[x]);  // n is 0 only in a 1x1 image
}

// One colour's half-sweep of the pixels [lo, hi] of row y. Inside the image's border
// every pixel has four neighbours: the step is computed for the whole run into `step`
// and added times the 0/1 selection, so both loops vectorise (the other colour's pixels
// are only read, so computing their steps too changes nothing).
void relax_run(cv::Mat& f, const uint8_t* selected, int y, int lo, int hi, float omega, std::vector<float>& step) {
  if (y == 0 || y + 1 == f.rows) {
    for (int x = lo; x <= hi; ++x)
      if (selected[x]) relax_pixel(f, y, x, omega);
    return;
  }
  if (lo == 0 && selected[lo++]) relax_pixel(f, y, 0, omega);
  if (hi == f.cols - 1 && selected[hi--]) relax_pixel(f, y, f.cols - 1, omega);
  float* __restrict row = f.ptr<float>(y);
  const float* __restrict up = f.ptr<float>(y - 1);
  const float* __restrict down = f.ptr<float>(y + 1);
  float* __restrict out = step.data();
  for (int x = lo; x <= hi; ++x)  // * 0.25 is exactly / 4
    out[x] = omega * ((row[x - 1] + row[x + 1] + up[x] + down[x]) * 0.25f - row[x]);
  for (int x = lo; x <= hi; ++x) row[x] += out[x] * float(selected[x]);
}

void relax_row(cv::Mat& f, const Unknowns& u, int colour, int y, float omega, std::vector<float>& step) {
  const uint8_t* selected = u.selected[colour].ptr<uint8_t>(y);
  for (const cv::Range& r : u.runs[y]) relax_run(f, selected, y, r.start, r.end - 1, omega, step);
}

// `iterations` red-black sweeps of one colour channel. A half-sweep (stage) of row y only
// reads rows y - 1..y + 1 as the previous stage left them, so stage s can run on row
// t - 2 s at step t: a wavefront of 2 kFusedIterations stages, 2 rows apart, gives the
// very values of sweeping the whole image stage after stage, from a window that fits in
// cache.
void relax_plane(cv::Mat& f, const Unknowns& u, int iterations, float omega) {
  std::vector<float> step(f.cols);
  for (int done = 0; done < iterations; done += kFusedIterations) {
    const int stages = 2 * std::min(kFusedIterations, iterations - done);  // stage s: colour s & 1
    for (int t = 0; t < f.rows + 2 * (stages - 1); ++t)
      for (int s = 0; s < stages; ++s) {
        const int y = t - 2 * s;
        if (y >= 0 && y < f.rows) relax_row(f, u, s & 1, y, omega, step);
      }
  }
}

void check_params(const HarmonicFill& p) {
  if (p.coarsest_side < 1 || p.start_side < p.coarsest_side || p.coarsest_sweeps < 0 || p.sweeps < 0 ||
      p.band < 0 || !(p.omega > 0 && p.omega < 2))
    throw std::invalid_argument(
        "harmonic_fill: needs 1 <= coarsest_side <= start_side, sweeps and band >= 0, omega in (0, 2)");
}

// One level of the cascade: the known pixels, which the sweeps keep, and their colour.
struct Level {
  cv::Mat colour;  // CV_32FC3; only read where known
  cv::Mat known;   // CV_8UC1
};

// Halves each side ((n + 1) / 2, as push-pull's pyramid) until the long side is at most
// coarsest_side, or a level would have no known cell. A coarse cell is known when at
// least kKnownShare of its area is, and then holds the mean of its known pixels'
// colours (the others hold 0 until solved).
std::vector<Level> cascade_levels(const cv::Mat& colour, const cv::Mat& known, int coarsest_side) {
  std::vector<Level> levels{{colour, known}};
  cv::Mat weight, weight3, weighted;  // known share of each cell; colour x that share
  known.convertTo(weight, CV_32F, 1.0 / 255.0);
  cv::threshold(weight, weight, 0.0, 1.0, cv::THRESH_BINARY);
  cv::merge(std::vector<cv::Mat>(3, weight), weight3);
  weighted = colour.mul(weight3);
  weight3.release();  // a full-size image no longer needed: the levels below are smaller
  while (std::max(levels.back().colour.cols, levels.back().colour.rows) > coarsest_side) {
    const cv::Size half((levels.back().colour.cols + 1) / 2, (levels.back().colour.rows + 1) / 2);
    cv::resize(weight, weight, half, 0, 0, cv::INTER_AREA);
    cv::resize(weighted, weighted, half, 0, 0, cv::INTER_AREA);
    Level coarse;
    coarse.known = weight >= kKnownShare;
    if (cv::countNonZero(coarse.known) == 0) break;  // scattered known pixels: stay finer
    cv::merge(std::vector<cv::Mat>(3, weight), weight3);
    coarse.colour = cv::Mat::zeros(half, CV_32FC3);
    const cv::Mat known_mean = weighted / cv::max(weight3, 1e-12);  // read where known
    known_mean.copyTo(coarse.colour, coarse.known);
    levels.push_back(coarse);
  }
  return levels;
}

// `sweeps` red-black sweeps of `f` (CV_32FC3) keeping the known pixels and, when band > 0,
// every pixel more than `band` 3x3 dilations away from them; the channels are
// independent, one task each.
void relax(cv::Mat& f, const cv::Mat& known, int sweeps, float omega, int band, ThreadPool& pool) {
  if (sweeps == 0) return;
  cv::Mat near;
  if (band > 0) cv::dilate(known, near, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}), {-1, -1}, band);
  // a new matrix: assigning the expression to a header of `known` would write into it
  const cv::Mat fixed = band > 0 ? cv::Mat(known | (near == 0)) : known;
  const Unknowns u = unknown_pixels(fixed);
  std::vector<cv::Mat> planes;
  cv::split(f, planes);
  pool.parallel_for(3, 1, [&](int64_t c0, int64_t c1) {
    for (int64_t c = c0; c < c1; ++c) relax_plane(planes[c], u, sweeps, omega);
  });
  cv::merge(planes, f);
}

// The coarsest level's start: push-pull's estimate on the first level at most start_side
// pixels, averaged down level by level with the known cells set to their colour.
cv::Mat coarsest_start(const std::vector<Level>& levels, int start_side) {
  size_t l = 0;
  while (l + 1 < levels.size() && std::max(levels[l].colour.cols, levels[l].colour.rows) > start_side) ++l;
  cv::Mat start = push_pull_estimate(levels[l].colour, levels[l].known);
  for (++l; l < levels.size(); ++l) {
    cv::resize(start, start, levels[l].colour.size(), 0, 0, cv::INTER_AREA);
    levels[l].colour.copyTo(start, levels[l].known);
  }
  return start;
}

}  // namespace

cv::Mat harmonic_estimate(const cv::Mat& image, const cv::Mat& known, const HarmonicFill& params,
                          ThreadPool& pool) {
  check_params(params);
  check_fill_inputs("harmonic_fill", image, known);
  if (cv::countNonZero(known) == 0) return cv::Mat();  // nothing to spread
  cv::Mat bgr, colour;
  if (image.channels() == 4)
    cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
  else
    bgr = image;
  bgr.convertTo(colour, CV_32F);
  bgr.release();
  std::vector<Level> levels = cascade_levels(colour, known, params.coarsest_side);
  colour.release();  // levels[0] holds it
  cv::Mat estimate = coarsest_start(levels, params.start_side);
  relax(estimate, levels.back().known, params.coarsest_sweeps, params.omega, 0, pool);
  for (size_t l = levels.size() - 1; l-- > 0;) {
    // the coarser solution, brought up, starts the unknown pixels of this level
    cv::Mat up;
    cv::resize(estimate, up, levels[l].colour.size(), 0, 0, cv::INTER_LINEAR);
    // The level's colours are read only here: the estimate takes them over (at the full
    // size of a 4K layer, 100 MB not copied).
    estimate = std::move(levels[l].colour);
    up.copyTo(estimate, levels[l].known == 0);
    up.release();
    relax(estimate, levels[l].known, params.sweeps, params.omega, params.band, pool);
  }
  return estimate;
}

cv::Mat harmonic_fill(const cv::Mat& image, const cv::Mat& known, const cv::Mat& fill,
                      const HarmonicFill& params, ThreadPool& pool) {
  check_fill_inputs("harmonic_fill", image, known, fill);
  const cv::Mat estimate = harmonic_estimate(image, known, params, pool);
  return estimate.empty() ? image.clone() : paste_estimate(image, estimate, fill);
}

}  // namespace ampi
