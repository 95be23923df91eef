// Novel views of an MPI. Each layer is premultiplied once into a padded half-float BGRA
// block, the box around its visible pixels (about half of the frame for the layers of a
// 4K photo; the rest is transparent and not stored); a frame is split into tiles that
// the thread pool renders independently: for every tile, each plane whose warped
// footprint can reach the tile is sampled through its inverse homography (bilinear) and
// composited back to front with the *over* operator.
// Planes behind one that is opaque over the whole tile are skipped: over an opaque sample
// the accumulator is multiplied by exactly zero, so the frame is the same bit for bit.
#pragma once
#include <opencv2/core.hpp>
#include <vector>

#include "engine/isa.h"
#include "engine/thread_pool.h"
#include "mpi/mpi.h"
#include "render/composite_kernels.h"
#include "render/pose.h"

namespace ampi {

struct RendererOptions {
  // Tiles are the unit of parallel work and of plane skipping; the accumulator of one
  // tile (width x height x 16 bytes) should stay in the L1/L2 cache.
  int tile_width = 64;
  int tile_height = 16;
  Isa isa = active_isa();  // which compositor kernels run (tests force each)
  // Skip the planes that give a tile nothing or are hidden there behind an opaque plane.
  // Exact (the frame is the same bit for bit); off only to measure what it saves.
  bool cull = true;
};

class Renderer {
 public:
  // Validates the MPI (throws std::invalid_argument naming the problem) and prepares
  // its layers; the Renderer does not keep a reference to `mpi`.
  explicit Renderer(const Mpi& mpi, RendererOptions options = {});
  // The same, letting each 8-bit layer of `mpi` go as soon as its half-float copy is
  // made, so the two never coexist for all layers (at 3840x2160, 265 MB of 8-bit layers
  // beside the renderer's 530 MB). `mpi` keeps its camera and planes, no layers.
  explicit Renderer(Mpi&& mpi, RendererOptions options = {});

  // The view from `pose` as 8-bit BGR (the composite over black), camera-sized.
  cv::Mat render(const Pose& pose) const { return render(pose, default_pool()); }
  cv::Mat render(const Pose& pose, ThreadPool& pool) const;
  // Same, into `out` (reallocated only if its size or type differ).
  void render(const Pose& pose, cv::Mat& out, ThreadPool& pool) const;

 private:
  // A layer's coverage by blocks of kBlock x kBlock pixels, as summed-area tables over
  // blocks: which hold any visible pixel, which are entirely opaque.
  struct Coverage {
    static constexpr int kBlock = 16;
    cv::Mat visible_sums, opaque_sums;  // CV_32S, (blocks_y + 1) x (blocks_x + 1)
    bool any_visible(const cv::Rect& pixels) const;
    bool all_opaque(const cv::Rect& pixels) const;
  };
  struct Layer {
    // CV_16FC4 premultiplied BGRA: the box around the visible pixels only, with the
    // border PlaneView describes
    cv::Mat padded;
    render::PlaneView view;
    double depth = 0;
    Coverage coverage;
  };
  struct PlaneMap {
    render::InverseHomography inverse;
    cv::Matx33d inverse_d;
    bool translation = false;  // inverse is (x, y) -> (x + du, y + dv)
    float du = 0, dv = 0;
  };
  static PlaneMap plane_map(const cv::Matx33d& inverse);
  // What a tile of the new view receives from a plane: nothing (skip it), some pixels,
  // or opaque pixels only (the planes behind it are hidden there).
  enum class TileCover { None, Partial, Opaque };

  static cv::Rect visible_box(const cv::Mat& bgra);
  static Layer prepare_layer(const cv::Mat& bgra, double depth);
  void check_setup(const Mpi& mpi) const;
  static Coverage coverage_of(const cv::Mat& bgra);
  static TileCover tile_cover(const Layer& layer, const PlaneMap& map, const cv::Rect& tile);
  void render_tile(const std::vector<PlaneMap>& maps, const cv::Rect& tile, float* accum,
                   std::vector<TileCover>& covers, cv::Mat& out) const;

  Camera camera_;
  RendererOptions options_;
  render::CompositeKernels kernels_;
  std::vector<Layer> layers_;  // back to front
};

// The reference: per plane, cv::warpPerspective of the premultiplied layer (bilinear,
// transparent outside) and an *over* blend in float, one plane after another.
cv::Mat render_naive(const Mpi& mpi, const Pose& pose);

// Throws std::invalid_argument if the MPI cannot be rendered: no planes, layers that
// are not CV_8UC4 of the camera's size, depths that are not positive and decreasing.
void validate_mpi(const Mpi& mpi);

}  // namespace ampi
