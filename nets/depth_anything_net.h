// Depth Anything V2 (Yang et al. 2024): a DINOv2 vision transformer and a DPT head, built
// from a weight file written by training/import_depth_anything.py (arch
// ampi.depth.dav2-vit-dpt; training/DEPTH_ANYTHING.md has the layout). vits, vitb and
// vitl differ only in the dav2.* dimensions of the file's metadata.
//
//   std::unique_ptr<DepthModel> net = load_depth_model("weights/dav2_vits.ampw");
//   Tensor disparity = net->run(rgb, h, w, pool);   // [h][w], larger = nearer
//
// run() does the reference preprocessing itself (the twin's `infer`): the photo resized
// bicubically, aspect kept, so that its shorter side reaches the working size and both
// sides are multiples of the patch (working_shape); normalised; the network; the output
// resized back to the photo's size bilinearly with align_corners. Callers hand it the
// photo at its own size (input_size). The network is planned once per working shape on
// the shared executor (nets/plan.h).
#pragma once
#include <memory>
#include <string>

#include "engine/tensor.h"
#include "engine/thread_pool.h"
#include "kernels/kernel_table.h"
#include "nets/depth_model.h"
#include "weights_format/weight_file.h"

namespace ampi {

// The network input shape for a height x width photo at working size `size` (the
// reference's "lower_bound" rule): scaled, aspect kept, so the shorter side reaches
// `size`; each side rounded to the nearest multiple (halves to even) and raised to the
// next multiple if that fell below `size`.
ImageSize dav2_working_shape(int height, int width, int size, int multiple);

class DepthAnythingNet final : public DepthModel {
 public:
  // Checks `file` (every dav2.* and depth.* key, every tensor's shape by name) and packs
  // its weights for the table. Throws std::runtime_error("PATH: problem").
  static DepthAnythingNet from_file(const WeightFile& file, const KernelTable& table = kernels());

  DepthAnythingNet(DepthAnythingNet&&) noexcept;
  DepthAnythingNet& operator=(DepthAnythingNet&&) noexcept;
  ~DepthAnythingNet() override;

  Tensor run(const float* rgb, int h, int w, ThreadPool& pool = default_pool()) override;

  const std::string& architecture() const override;
  const std::string& variant() const override;
  // The shorter side of the network input (depth.working_size, 518 for the official
  // models); set_working_size takes multiple()..16384.
  int working_size() const override;
  void set_working_size(int size) override;
  ImageSize input_size(int height, int width) const override { return {height, width}; }
  int multiple() const;  // the patch size
  int64_t parameter_count() const override;
  size_t arena_bytes() const override;

 private:
  struct Impl;
  explicit DepthAnythingNet(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace ampi
