#include "slicing/assemble.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "slicing/adaptive.h"

namespace ampi {
namespace {

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

void check_inputs(const cv::Mat& bgr, const cv::Mat& disparity, const std::vector<Plane>& planes,
                  const Camera& cam, double soft_alpha) {
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw std::invalid_argument("assemble_mpi: the photo must be a non-empty 8-bit BGR image");
  if (disparity.size() != bgr.size())
    throw std::invalid_argument("assemble_mpi: disparity is " + size_text(disparity.cols, disparity.rows) +
                                " but the photo is " + size_text(bgr.cols, bgr.rows));
  if (cam.width != bgr.cols || cam.height != bgr.rows)
    throw std::invalid_argument("assemble_mpi: camera is for " + size_text(cam.width, cam.height) +
                                " but the photo is " + size_text(bgr.cols, bgr.rows));
  if (planes.empty()) throw std::invalid_argument("assemble_mpi: no planes");
  for (size_t j = 1; j < planes.size(); ++j)
    if (planes[j].disparity_lo < planes[j - 1].disparity_hi)
      throw std::invalid_argument("assemble_mpi: planes must be back to front with disjoint intervals");
  if (!(soft_alpha >= 0)) throw std::invalid_argument("assemble_mpi: soft_alpha must not be negative");
}

std::vector<cv::Mat> empty_layers(size_t n, cv::Size size) {
  std::vector<cv::Mat> layers(n);
  for (cv::Mat& layer : layers) layer = cv::Mat::zeros(size, CV_8UC4);
  return layers;
}

// The paper's cut: every pixel goes, opaque, to the one plane that holds its level.
std::vector<cv::Mat> hard_layers(const cv::Mat& bgr, const cv::Mat& disparity,
                                 const std::vector<Plane>& planes) {
  const cv::Mat levels = normalize_disparity(disparity);
  int plane_of[kDisparityLevels];
  for (int level = 0; level < kDisparityLevels; ++level) plane_of[level] = plane_of_level(planes, level);
  std::vector<cv::Mat> layers = empty_layers(planes.size(), bgr.size());
  for (int y = 0; y < bgr.rows; ++y) {
    const uchar* level = levels.ptr<uchar>(y);
    const cv::Vec3b* colour = bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < bgr.cols; ++x) {
      const int j = plane_of[level[x]];
      if (j >= 0) layers[j].ptr<cv::Vec4b>(y)[x] = {colour[x][0], colour[x][1], colour[x][2], 255};
    }
  }
  return layers;
}

// Alpha of plane j for an unrounded level v: it fades in across the cut below it and
// stays opaque up to the end of the next plane's fade-in, so plane j covers whatever the
// nearer plane leaves uncovered. The cut between planes j-1 and j is where rounding
// switches to plane j's first level.
float soft_alpha_of(const std::vector<Plane>& planes, size_t j, float v, float width) {
  const auto cut_below = [&](size_t k) { return static_cast<float>(planes[k].disparity_lo) - 0.5f; };
  float alpha = 1.0f;
  if (j > 0) alpha = std::clamp((v - cut_below(j)) / width + 0.5f, 0.0f, 1.0f);
  if (j + 1 < planes.size() && v >= cut_below(j + 1) + 0.5f * width) alpha = 0.0f;
  return alpha;
}

std::vector<cv::Mat> soft_layers(const cv::Mat& bgr, const cv::Mat& disparity,
                                 const std::vector<Plane>& planes, double soft_alpha) {
  const cv::Mat values = normalize_disparity_float(disparity);
  const float width = static_cast<float>(soft_alpha);
  std::vector<cv::Mat> layers = empty_layers(planes.size(), bgr.size());
  for (size_t j = 0; j < planes.size(); ++j) {
    for (int y = 0; y < bgr.rows; ++y) {
      const float* v = values.ptr<float>(y);
      const cv::Vec3b* colour = bgr.ptr<cv::Vec3b>(y);
      cv::Vec4b* out = layers[j].ptr<cv::Vec4b>(y);
      for (int x = 0; x < bgr.cols; ++x) {
        const int alpha = cvRound(255.0f * soft_alpha_of(planes, j, v[x], width));
        if (alpha > 0) out[x] = {colour[x][0], colour[x][1], colour[x][2], static_cast<uchar>(alpha)};
      }
    }
  }
  return layers;
}

}  // namespace

Mpi assemble_mpi(const cv::Mat& bgr, const cv::Mat& disparity, const std::vector<Plane>& planes,
                 const Camera& cam, const DepthRange& range, double soft_alpha) {
  check_inputs(bgr, disparity, planes, cam, soft_alpha);
  Mpi mpi;
  mpi.camera = cam;
  mpi.range = range;
  mpi.planes = planes;
  mpi.layers = soft_alpha > 0 ? soft_layers(bgr, disparity, planes, soft_alpha)
                              : hard_layers(bgr, disparity, planes);
  return mpi;
}

namespace {

// Per pixel: 1 + the index of the layer that holds it (layers are back to front, so a
// larger owner is nearer), 0 where no layer does.
cv::Mat layer_owners(const Mpi& mpi) {
  cv::Mat owner(mpi.layers[0].size(), CV_16UC1, cv::Scalar(0));
  for (size_t j = 0; j < mpi.layers.size(); ++j) {
    cv::Mat alpha;
    cv::extractChannel(mpi.layers[j], alpha, 3);
    owner.setTo(cv::Scalar(double(j + 1)), alpha > 0);
  }
  return owner;
}

}  // namespace

int64_t feather_depth_edges(Mpi& mpi, const cv::Mat& bgr, const cv::Mat& band, int width) {
  if (mpi.layers.empty() || width <= 0) return 0;
  const cv::Size size = mpi.layers[0].size();
  if (bgr.size() != size || bgr.type() != CV_8UC3 || band.size() != size || band.type() != CV_8UC1)
    throw std::invalid_argument("feather_depth_edges: the photo and the band must be of the layers' size");
  const cv::Mat owner = layer_owners(mpi);
  // Dilating the owners spreads the nearer layers outwards one pixel per step: after r
  // steps a pixel holds the nearest layer within chessboard distance r.
  cv::Mat reach = owner.clone(), moved(size, CV_8UC1, cv::Scalar(0));
  int64_t count = 0;
  for (int r = 1; r <= width; ++r) {
    cv::dilate(reach, reach, cv::Mat());
    const uchar alpha = static_cast<uchar>(std::lround(255.0 * (width + 1 - r) / (width + 1)));
    for (int y = 0; y < size.height; ++y) {
      const uint16_t *own = owner.ptr<uint16_t>(y), *near = reach.ptr<uint16_t>(y);
      const uchar* edge = band.ptr<uchar>(y);
      uchar* done = moved.ptr<uchar>(y);
      const cv::Vec3b* colour = bgr.ptr<cv::Vec3b>(y);
      for (int x = 0; x < size.width; ++x) {
        if (!edge[x] || done[x] || own[x] == 0 || near[x] <= own[x]) continue;
        mpi.layers[own[x] - 1].ptr<cv::Vec4b>(y)[x] = {0, 0, 0, 0};
        mpi.layers[near[x] - 1].ptr<cv::Vec4b>(y)[x] = {colour[x][0], colour[x][1], colour[x][2], alpha};
        done[x] = 255;
        ++count;
      }
    }
  }
  return count;
}

}  // namespace ampi
