// The depth network (nets/ARCHITECTURE.md): MobileNetV3 blocks between Haar wavelet
// transforms, built from a weight file written by training/export_depth.py.
//
// Only the block types are known here (plain convolution, MobileNetV3 inverted residual)
// and the U-shaped wiring of the paper: DWT down, blocks, skip, IDWT up, blocks, head.
// Widths, block lists, kernel sizes, squeeze-excite widths, activations, the number of
// levels and the input normalisation all come from the file's metadata, and every
// tensor's shape is checked by name when it loads.
//
//   DepthNet net = DepthNet::from_file(WeightFile::open("weights/depth_lite.ampw"));
//   Tensor disparity = net.run(rgb, h, w, pool);   // [h][w], larger = nearer
//
// run() takes any size: the image is padded to the network's multiple by edge replication
// and the output cropped back. It runs on the shared executor (nets/plan.h), planned once
// per padded input size. Code that takes any depth family holds a DepthModel
// (nets/model_loader.h) instead.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "engine/tensor.h"
#include "engine/thread_pool.h"
#include "kernels/kernel_table.h"
#include "nets/depth_model.h"
#include "weights_format/weight_file.h"

namespace ampi {

class DepthNet final : public DepthModel {
 public:
  // Checks `file` (architecture arch::kDepthDwtMobileNetV3) and packs its weights for the
  // table's ISA. Throws std::runtime_error("PATH: problem"). Programs load any depth
  // family through load_depth_model (nets/model_loader.h).
  static DepthNet from_file(const WeightFile& file, const KernelTable& table = kernels());

  DepthNet(DepthNet&&) noexcept;
  DepthNet& operator=(DepthNet&&) noexcept;
  ~DepthNet() override;

  Tensor run(const float* rgb, int h, int w, ThreadPool& pool = default_pool()) override;

  const std::string& architecture() const override;
  const std::string& variant() const override;
  int multiple() const;  // the padding granularity (2^levels)
  // The long side photos are resized to: metadata depth.working_long_side (weights
  // trained on small images ask for a smaller working resolution), 1024 when absent;
  // set_working_size takes 1..16384 (run() pads to the multiple).
  int working_size() const override;
  void set_working_size(int size) override;
  ImageSize input_size(int height, int width) const override;
  int64_t parameter_count() const override;
  size_t arena_bytes() const override;

 private:
  struct Impl;
  explicit DepthNet(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace ampi
