// The depth network (nets/ARCHITECTURE.md): MobileNetV3 blocks between Haar wavelet
// transforms, built from a weight file written by training/export_depth.py.
//
// Only the block types are known here (plain convolution, MobileNetV3 inverted residual)
// and the U-shaped wiring of the paper: DWT down, blocks, skip, IDWT up, blocks, head.
// Widths, block lists, kernel sizes, squeeze-excite widths, activations, the number of
// levels and the input normalisation all come from the file's metadata, and every
// tensor's shape is checked by name when it loads.
//
//   DepthNet net = DepthNet::load("weights/depth_lite.ampw");
//   Tensor disparity = net.run(rgb, h, w, pool);   // [h][w], larger = nearer
//
// run() takes any size: the image is padded to the network's multiple by edge replication
// and the output cropped back. Every intermediate activation lives in one arena, planned
// once per padded input size, with buffers of disjoint lifetimes sharing memory.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "engine/tensor.h"
#include "engine/thread_pool.h"
#include "kernels/kernel_table.h"

namespace ampi {

struct ImageSize {
  int height = 0, width = 0;
};

// The working resolution for a photo: its long side scaled to `max_side`, the aspect
// kept, never larger than the photo itself (no upscaling). Sides are at least 1.
ImageSize depth_working_size(int height, int width, int max_side = 1024);

class DepthNet {
 public:
  // Reads and checks `path` (a weight file of architecture "ampi.depth.dwt-mobilenetv3");
  // packs the weights for the table's ISA. Throws std::runtime_error("PATH: problem").
  static DepthNet load(const std::string& path, const KernelTable& table = kernels());

  DepthNet(DepthNet&&) noexcept;
  DepthNet& operator=(DepthNet&&) noexcept;
  ~DepthNet();

  // rgb: [h][w][3] floats in [0, 1] (the file's normalisation is applied here).
  // Returns the disparity, an f32 tensor of shape {h, w} (relative; larger = nearer).
  // One run at a time per DepthNet: the plan and its arena are reused between runs.
  Tensor run(const float* rgb, int h, int w, ThreadPool& pool = default_pool());

  const std::string& variant() const;  // "lite", "heavy", ... as the file names it
  int multiple() const;                // the padding granularity (2^levels)
  // The long side the weights work best at (metadata depth.working_long_side: weights
  // trained on small images ask for a smaller working resolution); 1024 when absent.
  int working_long_side() const;
  int64_t parameter_count() const;     // weights and biases the inference graph uses
  // Bytes of the activation arena of the last run (0 before the first).
  size_t arena_bytes() const;

 private:
  struct Impl;
  explicit DepthNet(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace ampi
