// What every depth network offers the pipeline, whatever its architecture: an RGB image
// in, a relative disparity map of the same size out. nets/model_loader.h builds one from
// any depth weight file.
#pragma once
#include <cstdint>
#include <string>

#include "engine/tensor.h"
#include "engine/thread_pool.h"

namespace ampi {

struct ImageSize {
  int height = 0, width = 0;
};

// The working resolution for a photo: its long side scaled to `max_side`, the aspect
// kept, never larger than the photo itself (no upscaling). Sides are at least 1.
ImageSize depth_working_size(int height, int width, int max_side = 1024);

class DepthModel {
 public:
  virtual ~DepthModel() = default;

  // rgb: [h][w][3] floats in [0, 1] (the file's own normalisation is applied inside).
  // Returns the disparity, an f32 tensor of shape {h, w} (relative; larger = nearer).
  // One run at a time per model: plans and arenas are reused between runs.
  virtual Tensor run(const float* rgb, int h, int w, ThreadPool& pool = default_pool()) = 0;

  virtual const std::string& architecture() const = 0;  // the file's `arch`
  virtual const std::string& variant() const = 0;       // "lite", "heavy", ... as the file names it
  // The working resolution run() computes at, the file's by default: the photo's long
  // side for the wavelet networks (lite, heavy; their callers resize to it), the
  // network input's shorter side for Depth Anything V2 (it resizes inside).
  virtual int working_size() const = 0;
  // Throws std::invalid_argument ("working size N is not in A..B") for a size the
  // network cannot run at.
  virtual void set_working_size(int size) = 0;
  // The size a caller resizes a height x width photo to before run(): the wavelet
  // networks' working resolution (depth_working_size), the photo itself for a network
  // that does its own resizing.
  virtual ImageSize input_size(int height, int width) const = 0;
  virtual int64_t parameter_count() const = 0;  // weights and biases the inference graph uses
  // Bytes of the activation arena of the last run (0 before the first).
  virtual size_t arena_bytes() const = 0;
};

}  // namespace ampi
