#include "eval/edge_eval.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

#include "inpaint/push_pull.h"
#include "render/renderer.h"

namespace ampi {
namespace {

// Coverage of a shape given by an inside test, from 4 x 4 samples per pixel (pixel
// centres at integer coordinates).
cv::Mat coverage_of(cv::Size size, const std::function<bool(double, double)>& inside) {
  cv::Mat cov(size, CV_32FC1);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      int hits = 0;
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) hits += inside(x - 0.375 + 0.25 * j, y - 0.375 + 0.25 * i);
      cov.at<float>(y, x) = hits / 16.0f;
    }
  return cov;
}

// Smooth noise in [-1, 1]: octaves of uniform noise enlarged bicubically.
cv::Mat smooth_noise(cv::Size size, std::mt19937& rng) {
  cv::Mat sum = cv::Mat::zeros(size, CV_32FC1);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const int cells[] = {6, 24, 96};
  const float weight[] = {0.5f, 0.3f, 0.2f};
  for (int o = 0; o < 3; ++o) {
    cv::Mat coarse(std::max(2, size.height * cells[o] / std::max(size.width, size.height)), cells[o], CV_32FC1);
    for (int y = 0; y < coarse.rows; ++y)
      for (int x = 0; x < coarse.cols; ++x) coarse.at<float>(y, x) = unit(rng);
    cv::Mat fine;
    cv::resize(coarse, fine, size, 0, 0, cv::INTER_CUBIC);
    sum += weight[o] * fine;
  }
  return cv::max(cv::min(sum, 1.0), -1.0);
}

// A texture of one hue family: `base` (BGR) varied in brightness by `amplitude` and,
// less, per channel.
cv::Mat noise_texture(cv::Size size, std::mt19937& rng, cv::Vec3f base, float amplitude) {
  const cv::Mat light = smooth_noise(size, rng);
  cv::Mat tint[3];
  for (cv::Mat& t : tint) t = smooth_noise(size, rng);
  cv::Mat out(size, CV_8UC3);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      for (int c = 0; c < 3; ++c)
        out.at<cv::Vec3b>(y, x)[c] = cv::saturate_cast<uchar>(
            base[c] + amplitude * light.at<float>(y, x) + 0.35f * amplitude * tint[c].at<float>(y, x));
  return out;
}

// A crop of the photo at a random place, scaled to `size`.
cv::Mat photo_texture(const cv::Mat& photo, cv::Size size, std::mt19937& rng) {
  const double scale = std::min(1.0, 0.7 * std::min(double(photo.cols) / size.width, double(photo.rows) / size.height));
  const int w = std::max(1, int(size.width * scale)), h = std::max(1, int(size.height * scale));
  std::uniform_int_distribution<int> x0(0, photo.cols - w), y0(0, photo.rows - h);
  cv::Mat crop;
  cv::resize(photo(cv::Rect(x0(rng), y0(rng), w, h)), crop, size, 0, 0, cv::INTER_AREA);
  return crop;
}

using Shape = std::function<bool(double, double)>;

struct SceneSpec {
  std::string name;
  std::vector<std::pair<Shape, double>> objects;  // back to front: shape, disparity
};

std::vector<SceneSpec> scene_specs(cv::Size size) {
  const double W = size.width, H = size.height;
  auto disk = [](double cx, double cy, double r) {
    return [=](double x, double y) { return (x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r; };
  };
  auto box = [](double x0, double y0, double x1, double y1) {
    return [=](double x, double y) { return x >= x0 && x < x1 && y >= y0 && y < y1; };
  };
  const double pole = std::max(6.0, W / 64);
  const Shape head = disk(0.5 * W, 0.28 * H, 0.08 * H);
  const Shape torso = [=](double x, double y) {
    const double u = (x - 0.5 * W) / (0.11 * H), v = (y - 0.52 * H) / (0.18 * H);
    return u * u + v * v <= 1;
  };
  const Shape legs = [=](double x, double y) {
    return box(0.5 * W - 0.09 * H, 0.62 * H, 0.5 * W - 0.015 * H, H)(x, y) ||
           box(0.5 * W + 0.015 * H, 0.62 * H, 0.5 * W + 0.09 * H, H)(x, y);
  };
  const Shape arms = [=](double x, double y) {
    return box(0.5 * W - 0.165 * H, 0.38 * H, 0.5 * W - 0.115 * H, 0.68 * H)(x, y) ||
           box(0.5 * W + 0.115 * H, 0.38 * H, 0.5 * W + 0.165 * H, 0.68 * H)(x, y);
  };
  const Shape person = [=](double x, double y) { return head(x, y) || torso(x, y) || legs(x, y) || arms(x, y); };
  return {
      {"disk", {{disk(0.5 * W, 0.5 * H, 0.25 * H), 1.0}}},
      {"pole", {{box(0.45 * W, 0.1 * H, 0.45 * W + pole, H), 1.0}}},
      {"person", {{person, 1.0}}},
      // The disk lies inside the box, so every border of the box shows in the photo.
      {"two-objects", {{box(0.2 * W, 0.2 * H, 0.6 * W, 0.8 * H), 0.6}, {disk(0.42 * W, 0.5 * H, 0.15 * H), 1.0}}},
  };
}

double level_of(double d, double lo, double hi) { return hi > lo ? 255.0 * (d - lo) / (hi - lo) : 0.0; }

cv::Mat warp(const cv::Mat& image, const cv::Matx33d& homography, cv::Size size) {
  cv::Mat out;
  cv::warpPerspective(image, out, cv::Mat(homography), size, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar());
  return out;
}

}  // namespace

std::vector<EdgeScene> edge_scenes(cv::Size size, uint32_t seed, const cv::Mat& texture_photo) {
  if (size.width < 64 || size.height < 48) throw std::invalid_argument("edge_scenes: the size must be at least 64x48");
  if (!texture_photo.empty() && texture_photo.type() != CV_8UC3)
    throw std::invalid_argument("edge_scenes: the texture photo must be 8-bit BGR");
  std::mt19937 rng(seed);
  const cv::Vec3f hues[] = {{110, 150, 100}, {50, 60, 190}, {190, 90, 50}};  // BGR: green-grey, red, blue
  auto texture = [&](int k) {
    return texture_photo.empty() ? noise_texture(size, rng, hues[k], 40) : photo_texture(texture_photo, size, rng);
  };
  std::vector<EdgeScene> scenes;
  for (const SceneSpec& spec : scene_specs(size)) {
    EdgeScene scene;
    scene.name = spec.name;
    scene.surfaces.push_back({"background", texture(0), cv::Mat(size, CV_32FC1, cv::Scalar(1)), 0.25});
    for (size_t k = 0; k < spec.objects.size(); ++k)
      scene.surfaces.push_back({"object " + std::to_string(k + 1), texture(1 + int(k % 2)),
                                coverage_of(size, spec.objects[k].first), spec.objects[k].second});
    cv::Mat photo(size, CV_32FC3, cv::Scalar(0, 0, 0));
    scene.disparity = cv::Mat(size, CV_32FC1, cv::Scalar(0));
    for (const EdgeSurface& s : scene.surfaces) {
      cv::Mat tex, cov3;
      s.bgr.convertTo(tex, CV_32FC3);
      cv::merge(std::vector<cv::Mat>(3, s.coverage), cov3);
      photo = photo.mul(cv::Scalar(1, 1, 1) - cov3) + tex.mul(cov3);
      scene.disparity.setTo(cv::Scalar(s.disparity), s.coverage >= 0.5f);
    }
    photo.convertTo(scene.photo, CV_8UC3);
    scenes.push_back(std::move(scene));
  }
  return scenes;
}

cv::Mat soften_disparity(const cv::Mat& disparity, int factor) {
  if (factor < 1) throw std::invalid_argument("soften_disparity: factor must be at least 1");
  if (factor == 1) return disparity.clone();
  cv::Mat small, soft;
  cv::resize(disparity, small, {std::max(1, disparity.cols / factor), std::max(1, disparity.rows / factor)}, 0, 0,
             cv::INTER_AREA);
  cv::resize(small, soft, disparity.size(), 0, 0, cv::INTER_LINEAR);
  return soft;
}

Mpi exact_mpi(const EdgeScene& scene, const Camera& camera, const DepthRange& range) {
  double lo = scene.surfaces[0].disparity, hi = lo;
  for (const EdgeSurface& s : scene.surfaces) lo = std::min(lo, s.disparity), hi = std::max(hi, s.disparity);
  Mpi mpi;
  mpi.camera = camera;
  mpi.range = range;
  for (const EdgeSurface& s : scene.surfaces) {
    Plane plane;
    plane.disparity = level_of(s.disparity, lo, hi);
    plane.disparity_lo = plane.disparity_hi = plane.disparity;
    plane.depth = depth_from_disparity(plane.disparity, range);
    mpi.planes.push_back(plane);
    cv::Mat alpha, layer;
    s.coverage.convertTo(alpha, CV_8UC1, 255.0);
    cv::merge(std::vector<cv::Mat>{s.bgr, alpha}, layer);  // 3 + 1 channels: BGRA
    mpi.layers.push_back(layer);
  }
  return mpi;
}

EdgeJudge::EdgeJudge(const EdgeScene& scene, const Camera& camera, const DepthRange& range)
    : exact_(exact_mpi(scene, camera, range)), camera_(camera) {
  validate_mpi(exact_);
  const size_t n = scene.surfaces.size();
  if (n > 3) throw std::invalid_argument("EdgeJudge: at most 3 surfaces (one label channel each)");
  // How much of each photo pixel each surface makes: its coverage times what the nearer
  // surfaces leave uncovered.
  source_weights_ = cv::Mat(camera.height, camera.width, CV_32FC3, cv::Scalar(0, 0, 0));
  cv::Mat uncovered(camera.height, camera.width, CV_32FC1, cv::Scalar(1));
  for (size_t s = n; s-- > 0;) {
    const cv::Mat weight = scene.surfaces[s].coverage.mul(uncovered);
    cv::insertChannel(weight, source_weights_, int(s));
    uncovered = uncovered.mul(1.0f - scene.surfaces[s].coverage);
  }
  hidden_.resize(n);
  cv::Mat nearer(camera.height, camera.width, CV_32FC1, cv::Scalar(0));
  for (size_t s = n; s-- > 0;) {  // front to back
    hidden_[s] = cv::Mat(nearer >= 0.5f) / 255;
    hidden_[s].convertTo(hidden_[s], CV_32FC1);
    nearer = cv::max(nearer, scene.surfaces[s].coverage);
  }
}

cv::Mat EdgeJudge::exact_view(const Pose& pose) const { return Renderer(exact_).render(pose); }

Mpi EdgeJudge::label_mpi(const Mpi& mpi, const std::vector<cv::Mat>& fill_masks) const {
  const cv::Size size(camera_.width, camera_.height);
  validate_mpi(mpi);
  if (mpi.camera.width != size.width || mpi.camera.height != size.height)
    throw std::invalid_argument("EdgeJudge: the MPI is not of the scene's size");
  if (fill_masks.size() != mpi.layers.size()) throw std::invalid_argument("EdgeJudge: one fill mask per layer");
  Mpi labels = mpi;
  for (size_t j = 0; j < mpi.layers.size(); ++j) {
    cv::Mat alpha, colour;
    cv::extractChannel(mpi.layers[j], alpha, 3);
    const cv::Mat filled = (alpha > 0) & (fill_masks[j] != 0);
    const cv::Mat own = (alpha > 0) & (fill_masks[j] == 0);  // these show the photo
    cv::Mat weights(size, CV_32FC3, cv::Scalar(0, 0, 0));
    source_weights_.copyTo(weights, own);
    if (cv::countNonZero(filled) > 0 && cv::countNonZero(own) > 0) push_pull_estimate(weights, own).copyTo(weights, filled);
    weights.convertTo(colour, CV_8UC3, 255.0);
    labels.layers[j] = cv::Mat();  // a new image: the copy shares the MPI's
    cv::merge(std::vector<cv::Mat>{colour, alpha}, labels.layers[j]);
  }
  return labels;
}

EdgeScore EdgeJudge::score(const Mpi& mpi, const std::vector<cv::Mat>& fill_masks, const Pose& pose) const {
  const cv::Size size(camera_.width, camera_.height);
  const size_t n = exact_.layers.size();
  // Rendered labels: per pixel how much of each surface the MPI shows there (channel s
  // for surface s), summing to its coverage.
  cv::Mat shown;
  Renderer(label_mpi(mpi, fill_masks)).render(pose).convertTo(shown, CV_32FC3, 1.0 / 255);
  std::vector<cv::Mat> cover(n), revealed(n);
  std::vector<cv::Matx33d> h(n);
  for (size_t s = 0; s < n; ++s) {
    h[s] = plane_homography(camera_, pose, exact_.planes[s].depth);
    cv::Mat alpha;
    cv::extractChannel(exact_.layers[s], alpha, 3);
    alpha.convertTo(alpha, CV_32FC1, 1.0 / 255);
    cover[s] = warp(alpha, h[s], size);
    revealed[s] = warp(hidden_[s], h[s], size);
  }
  const cv::Mat frame = warp(cv::Mat(size, CV_32FC1, cv::Scalar(1)), h[0], size);
  // Mixed pixels: where an object's border passes in the exact view, one pixel around.
  cv::Mat mixed(size, CV_8UC1, cv::Scalar(0));
  for (size_t s = 1; s < n; ++s) mixed |= (cover[s] > 0.01f) & (cover[s] < 0.99f);
  cv::dilate(mixed, mixed, cv::Mat());

  EdgeScore score;
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      if (frame.at<float>(y, x) < 0.999f || mixed.at<uchar>(y, x)) continue;
      size_t owner = 0;
      for (size_t s = n; s-- > 1;)
        if (cover[s].at<float>(y, x) >= 0.5f) {
          owner = s;
          break;
        }
      if (owner > 0) ++score.object_pixels;
      const cv::Vec3f w = shown.at<cv::Vec3f>(y, x);
      if (w[0] + w[1] + w[2] < 0.5f) {  // nothing there: composited over black
        ++score.holes;
        score.wrong += owner > 0;
        continue;
      }
      size_t most = 0;
      for (size_t s = 1; s < n; ++s)
        if (w[int(s)] > w[int(most)]) most = s;
      if (w[int(owner)] >= 0.5f) continue;  // the right surface, at least half
      if (owner > 0 || most > 0) ++score.wrong;
      if (most > owner && revealed[owner].at<float>(y, x) >= 0.5f) ++score.fringe;
    }
  // The nearest object's motion against the background, at its centroid.
  cv::Mat nearest;
  cv::extractChannel(exact_.layers[n - 1], nearest, 3);
  const cv::Moments m = cv::moments(nearest);
  if (m.m00 > 0) {
    const cv::Vec3d c(m.m10 / m.m00, m.m01 / m.m00, 1);
    auto moved = [&](const cv::Matx33d& H) {
      const cv::Vec3d p = H * c;
      return cv::Vec2d(p[0] / p[2], p[1] / p[2]);
    };
    score.motion_px = cv::norm(moved(h[n - 1]) - moved(h[0]));
  }
  return score;
}

}  // namespace ampi
