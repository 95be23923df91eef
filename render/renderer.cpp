#include "render/renderer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace ampi {
namespace {

// Padding of the stored half-float blocks: two transparent pixels before each row and
// column (a footprint left of a block that starts inside the layer) and two after (the
// bilinear footprint of a coordinate clamped to the far edge).
constexpr int kPadBefore = 2;
constexpr int kPadAfter = 2;

// Straight-alpha BGRA bytes to premultiplied BGRA floats in [0, 1].
void premultiply_row(const uint8_t* in, int width, float* out) {
  for (int x = 0; x < width; ++x, in += 4, out += 4) {
    const float alpha = in[3] / 255.0f;
    for (int k = 0; k < 3; ++k) out[k] = in[k] / 255.0f * alpha;
    out[3] = alpha;
  }
}

cv::Mat premultiply(const cv::Mat& bgra) {
  cv::Mat out(bgra.size(), CV_32FC4);
  for (int y = 0; y < bgra.rows; ++y) premultiply_row(bgra.ptr<uint8_t>(y), bgra.cols, out.ptr<float>(y));
  return out;
}

// premultiply(bgra) converted to half floats into `halves`, a row at a time: the float
// image of a whole layer (133 MB at 3840x2160) is never held.
void premultiply_to_half(const cv::Mat& bgra, cv::Mat& halves) {
  cv::Mat row(1, bgra.cols, CV_32FC4);
  for (int y = 0; y < bgra.rows; ++y) {
    premultiply_row(bgra.ptr<uint8_t>(y), bgra.cols, row.ptr<float>());
    cv::Mat out = halves.row(y);
    row.convertTo(out, CV_16F);
  }
}

render::InverseHomography to_float(const cv::Matx33d& m) {
  render::InverseHomography h;
  for (int i = 0; i < 9; ++i) h.m[i] = static_cast<float>(m.val[i]);
  return h;
}

}  // namespace

void validate_mpi(const Mpi& mpi) {
  const Camera& c = mpi.camera;
  if (mpi.planes.empty()) throw std::invalid_argument("MPI has no planes");
  if (mpi.layers.size() != mpi.planes.size())
    throw std::invalid_argument("MPI has " + std::to_string(mpi.layers.size()) + " layers for " +
                                std::to_string(mpi.planes.size()) + " planes");
  if (c.width <= 0 || c.height <= 0 || !(c.fx > 0) || !(c.fy > 0))
    throw std::invalid_argument("MPI camera needs a positive image size and focal length");
  // The kernels index pixels of the padded planes with 32-bit integers.
  if (static_cast<int64_t>(c.width + kPadBefore + kPadAfter) * (c.height + kPadBefore + kPadAfter) >= (1LL << 31))
    throw std::invalid_argument("MPI layers of " + std::to_string(c.width) + "x" +
                                std::to_string(c.height) + " are too large to render");
  for (size_t j = 0; j < mpi.planes.size(); ++j) {
    const std::string which = "MPI layer " + std::to_string(j);
    const cv::Mat& layer = mpi.layers[j];
    if (layer.type() != CV_8UC4 || layer.cols != c.width || layer.rows != c.height)
      throw std::invalid_argument(which + " is not a " + std::to_string(c.width) + "x" +
                                  std::to_string(c.height) + " BGRA image");
    const double depth = mpi.planes[j].depth;
    if (!(depth > 0) || !std::isfinite(depth))
      throw std::invalid_argument(which + " has a depth that is not positive and finite");
    if (j > 0 && depth > mpi.planes[j - 1].depth)
      throw std::invalid_argument(which + " is farther than the layer before it "
                                  "(layers go back to front)");
  }
}

namespace {

int block_sum(const cv::Mat& sums, const cv::Rect& pixels, int block) {
  const int bx0 = pixels.x / block, by0 = pixels.y / block;
  const int bx1 = (pixels.br().x - 1) / block + 1, by1 = (pixels.br().y - 1) / block + 1;
  return sums.at<int>(by1, bx1) - sums.at<int>(by0, bx1) - sums.at<int>(by1, bx0) + sums.at<int>(by0, bx0);
}

int block_count(const cv::Rect& pixels, int block) {
  return ((pixels.br().x - 1) / block + 1 - pixels.x / block) * ((pixels.br().y - 1) / block + 1 - pixels.y / block);
}

}  // namespace

bool Renderer::Coverage::any_visible(const cv::Rect& pixels) const {
  return !pixels.empty() && block_sum(visible_sums, pixels, kBlock) > 0;
}

bool Renderer::Coverage::all_opaque(const cv::Rect& pixels) const {
  return !pixels.empty() && block_sum(opaque_sums, pixels, kBlock) == block_count(pixels, kBlock);
}

Renderer::Coverage Renderer::coverage_of(const cv::Mat& bgra) {
  const int blocks_x = (bgra.cols + Coverage::kBlock - 1) / Coverage::kBlock;
  const int blocks_y = (bgra.rows + Coverage::kBlock - 1) / Coverage::kBlock;
  cv::Mat visible(blocks_y, blocks_x, CV_8U, cv::Scalar(0)), opaque(blocks_y, blocks_x, CV_8U, cv::Scalar(1));
  for (int y = 0; y < bgra.rows; ++y) {
    const uint8_t* p = bgra.ptr<uint8_t>(y);
    uint8_t* visible_row = visible.ptr<uint8_t>(y / Coverage::kBlock);
    uint8_t* opaque_row = opaque.ptr<uint8_t>(y / Coverage::kBlock);
    for (int x = 0; x < bgra.cols; ++x) {
      const uint8_t alpha = p[4 * x + 3];
      if (alpha) visible_row[x / Coverage::kBlock] = 1;
      if (alpha != 255) opaque_row[x / Coverage::kBlock] = 0;
    }
  }
  Coverage c;
  cv::integral(visible, c.visible_sums, CV_32S);
  cv::integral(opaque, c.opaque_sums, CV_32S);
  return c;
}

// The box around a layer's visible pixels (alpha > 0); empty when none is.
cv::Rect Renderer::visible_box(const cv::Mat& bgra) {
  int x0 = bgra.cols, y0 = bgra.rows, x1 = 0, y1 = 0;  // x1, y1 exclusive
  for (int y = 0; y < bgra.rows; ++y) {
    const uint8_t* p = bgra.ptr<uint8_t>(y);
    int first = -1, last = -1;
    for (int x = 0; x < bgra.cols; ++x)
      if (p[4 * x + 3]) {
        if (first < 0) first = x;
        last = x;
      }
    if (first < 0) continue;
    x0 = std::min(x0, first);
    x1 = std::max(x1, last + 1);
    y0 = std::min(y0, y);
    y1 = y + 1;
  }
  return x1 > x0 ? cv::Rect(x0, y0, x1 - x0, y1 - y0) : cv::Rect();
}

// Only the box around the visible pixels is stored: outside it the layer is transparent,
// which the kernels read from the box's border (composite_kernels.h).
Renderer::Layer Renderer::prepare_layer(const cv::Mat& bgra, double depth) {
  Layer layer;
  layer.depth = depth;
  const cv::Rect box = visible_box(bgra);
  layer.padded = cv::Mat(box.height + kPadBefore + kPadAfter, box.width + kPadBefore + kPadAfter, CV_16FC4,
                         cv::Scalar::all(0));
  if (!box.empty()) {
    cv::Mat inside = layer.padded(cv::Rect(kPadBefore, kPadBefore, box.width, box.height));
    premultiply_to_half(bgra(box), inside);
  }
  layer.view.origin = layer.padded.ptr<uint16_t>(kPadBefore) + 4 * kPadBefore;
  layer.view.stride = static_cast<int64_t>(layer.padded.step1() / 4);
  layer.view.width = bgra.cols;
  layer.view.height = bgra.rows;
  layer.view.stored_x = box.x;
  layer.view.stored_y = box.y;
  layer.view.stored_width = box.width;
  layer.view.stored_height = box.height;
  layer.coverage = coverage_of(bgra);
  return layer;
}

Renderer::Renderer(const Mpi& mpi, RendererOptions options)
    : camera_(mpi.camera), options_(options), kernels_(render::composite_kernels(options.isa)) {
  check_setup(mpi);
  layers_.reserve(mpi.layers.size());
  for (size_t j = 0; j < mpi.layers.size(); ++j)
    layers_.push_back(prepare_layer(mpi.layers[j], mpi.planes[j].depth));
}

Renderer::Renderer(Mpi&& mpi, RendererOptions options)
    : camera_(mpi.camera), options_(options), kernels_(render::composite_kernels(options.isa)) {
  check_setup(mpi);
  layers_.reserve(mpi.layers.size());
  for (size_t j = 0; j < mpi.layers.size(); ++j) {
    layers_.push_back(prepare_layer(mpi.layers[j], mpi.planes[j].depth));
    mpi.layers[j].release();
  }
  std::vector<cv::Mat>().swap(mpi.layers);
}

void Renderer::check_setup(const Mpi& mpi) const {
  validate_mpi(mpi);
  if (options_.tile_width < 1 || options_.tile_height < 1)
    throw std::invalid_argument("renderer tiles must be at least 1x1 pixels");
}

// Camera moves parallel to the image plane (no rotation, zoom or motion along z) make
// every plane's map a translation, up to rounding in the matrix products.
Renderer::PlaneMap Renderer::plane_map(const cv::Matx33d& inverse) {
  PlaneMap map;
  map.inverse_d = inverse;
  map.inverse = to_float(inverse);
  constexpr double kTolerance = 1e-12;
  const cv::Matx33d& m = inverse;
  const bool affine_identity = std::fabs(m(2, 2) - 1) < kTolerance && std::fabs(m(0, 0) - 1) < kTolerance &&
                               std::fabs(m(1, 1) - 1) < kTolerance && std::fabs(m(0, 1)) < kTolerance &&
                               std::fabs(m(1, 0)) < kTolerance && std::fabs(m(2, 0)) < kTolerance &&
                               std::fabs(m(2, 1)) < kTolerance;
  if (affine_identity) {
    map.translation = true;
    map.du = static_cast<float>(m(0, 2));
    map.dv = static_cast<float>(m(1, 2));
  }
  return map;
}

// The tile's corners are mapped into the layer; when all lie in front of the camera, the
// image of the tile is inside their bounding box, and the pixels the bilinear footprints
// read inside that box grown by one pixel. The box is widened by a small margin because
// the kernels map coordinates in float, the box is computed in double.
Renderer::TileCover Renderer::tile_cover(const Layer& layer, const PlaneMap& map, const cv::Rect& tile) {
  constexpr double kMargin = 0.05;  // pixels; float rounding of the coordinates is far below
  double u_min = HUGE_VAL, u_max = -HUGE_VAL, v_min = HUGE_VAL, v_max = -HUGE_VAL;
  for (int corner = 0; corner < 4; ++corner) {
    const cv::Vec3d p = map.inverse_d * cv::Vec3d(corner & 1 ? tile.br().x - 1 : tile.x,
                                                  corner & 2 ? tile.br().y - 1 : tile.y, 1.0);
    if (!(p[2] > render::kMinHomogeneousW)) return TileCover::Partial;  // crosses the horizon
    u_min = std::min(u_min, p[0] / p[2] - kMargin);
    u_max = std::max(u_max, p[0] / p[2] + kMargin);
    v_min = std::min(v_min, p[1] / p[2] - kMargin);
    v_max = std::max(v_max, p[1] / p[2] + kMargin);
  }
  const int w = layer.view.width, h = layer.view.height;
  if (u_max < -1 || v_max < -1 || u_min > w || v_min > h) return TileCover::None;
  // Clamped first, as the kernels clamp, so the conversions to int cannot overflow.
  const int x0 = static_cast<int>(std::floor(std::max(u_min, -1.0)));
  const int y0 = static_cast<int>(std::floor(std::max(v_min, -1.0)));
  const int x1 = static_cast<int>(std::floor(std::min(u_max, double(w)))) + 2;  // exclusive
  const int y1 = static_cast<int>(std::floor(std::min(v_max, double(h)))) + 2;
  const cv::Rect read(x0, y0, x1 - x0, y1 - y0), inside(0, 0, w, h);
  if (!layer.coverage.any_visible(read & inside)) return TileCover::None;
  const bool reads_border = (read & inside) != read;
  return !reads_border && layer.coverage.all_opaque(read) ? TileCover::Opaque : TileCover::Partial;
}

void Renderer::render_tile(const std::vector<PlaneMap>& maps, const cv::Rect& tile, float* accum,
                           std::vector<TileCover>& covers, cv::Mat& out) const {
  // Front to back until a plane hides everything behind it; then draw back to front.
  const int planes = static_cast<int>(layers_.size());
  int first = 0;
  for (int j = planes - 1; j >= 0; --j) {
    covers[j] = options_.cull ? tile_cover(layers_[j], maps[j], tile) : TileCover::Partial;
    if (covers[j] == TileCover::Opaque) {
      first = j;
      break;
    }
  }
  const int row_floats = 4 * tile.width;
  std::fill(accum, accum + row_floats * tile.height, 0.0f);
  for (int j = first; j < planes; ++j) {
    if (covers[j] == TileCover::None) continue;
    const PlaneMap& map = maps[j];
    for (int r = 0; r < tile.height; ++r) {
      float* row = accum + r * row_floats;
      if (map.translation)
        kernels_.shift_over_row(layers_[j].view, map.du, map.dv, tile.y + r, tile.x, tile.width, row);
      else
        kernels_.warp_over_row(layers_[j].view, map.inverse, tile.y + r, tile.x, tile.width, row);
    }
  }
  for (int r = 0; r < tile.height; ++r)
    kernels_.accum_to_bgr(accum + r * row_floats, tile.width, out.ptr<uint8_t>(tile.y + r) + 3 * tile.x);
}

cv::Mat Renderer::render(const Pose& pose, ThreadPool& pool) const {
  cv::Mat out;
  render(pose, out, pool);
  return out;
}

void Renderer::render(const Pose& pose, cv::Mat& out, ThreadPool& pool) const {
  out.create(camera_.height, camera_.width, CV_8UC3);
  std::vector<PlaneMap> maps;
  for (const Layer& layer : layers_) maps.push_back(plane_map(plane_homography(camera_, pose, layer.depth).inv()));
  const int tw = options_.tile_width, th = options_.tile_height;
  const int tiles_x = (camera_.width + tw - 1) / tw, tiles_y = (camera_.height + th - 1) / th;
  pool.parallel_for(int64_t{tiles_x} * tiles_y, 1, [&](int64_t begin, int64_t end) {
    std::vector<float> accum(static_cast<size_t>(4) * tw * th);
    std::vector<TileCover> covers(layers_.size());
    for (int64_t t = begin; t < end; ++t) {
      const int x = static_cast<int>(t % tiles_x) * tw, y = static_cast<int>(t / tiles_x) * th;
      const cv::Rect tile(x, y, std::min(tw, camera_.width - x), std::min(th, camera_.height - y));
      render_tile(maps, tile, accum.data(), covers, out);
    }
  });
}

cv::Mat render_naive(const Mpi& mpi, const Pose& pose) {
  validate_mpi(mpi);
  const cv::Size size(mpi.camera.width, mpi.camera.height);
  cv::Mat accum(size, CV_32FC4, cv::Scalar::all(0)), warped, alpha, keep;
  for (size_t j = 0; j < mpi.layers.size(); ++j) {
    const cv::Matx33d h = plane_homography(mpi.camera, pose, mpi.planes[j].depth);
    cv::warpPerspective(premultiply(mpi.layers[j]), warped, h, size, cv::INTER_LINEAR,
                        cv::BORDER_CONSTANT, cv::Scalar::all(0));
    cv::extractChannel(warped, alpha, 3);
    cv::subtract(1.0, alpha, alpha);
    cv::merge(std::vector<cv::Mat>{alpha, alpha, alpha, alpha}, keep);
    accum = accum.mul(keep) + warped;
  }
  cv::Mat bgr, out;
  cv::cvtColor(accum, bgr, cv::COLOR_BGRA2BGR);
  bgr.convertTo(out, CV_8UC3, 255.0);
  return out;
}

}  // namespace ampi
