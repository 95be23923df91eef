// The engine's one data type: a dense array with a shape in numpy order, an element type
// and a layout tag.
//
// Activation layout is NHWC for the whole engine (batch 1 at inference, so H x W x C).
// Why: with channels innermost, a pointwise (1x1) convolution is a plain GEMM over
// pixels, a depthwise convolution vectorises across channels with no gathers, concat
// along channels is a strided copy, and the DWT's four bands concatenate on the same axis.
// Every kernel in kernels/ assumes it; see kernels/ops.h for the weight layouts.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace ampi {

enum class DType { F32, F16 };
enum class Layout { Plain, NHWC, OHWI };

size_t dtype_size(DType dtype);
const char* dtype_name(DType dtype);

using Shape = std::vector<int64_t>;
int64_t shape_numel(const Shape& shape);
std::string shape_str(const Shape& shape);  // "[1, 64, 64, 3]"

// Memory aligned to 64 bytes (one cache line, one AVX-512 register), freed with free().
struct AlignedDeleter {
  void operator()(void* p) const;
};
using AlignedBuffer = std::unique_ptr<void, AlignedDeleter>;
// Throws std::bad_alloc when the memory cannot be had.
AlignedBuffer aligned_alloc64(size_t bytes);

class Tensor {
 public:
  Tensor() = default;
  // Owned, 64-byte-aligned, uninitialised storage.
  static Tensor empty(const Shape& shape, DType dtype = DType::F32, Layout layout = Layout::Plain);
  static Tensor zeros(const Shape& shape, DType dtype = DType::F32, Layout layout = Layout::Plain);
  // A view of memory owned elsewhere (an arena, a mapped file); the owner outlives it.
  static Tensor view(void* data, const Shape& shape, DType dtype = DType::F32,
                     Layout layout = Layout::Plain);

  const Shape& shape() const { return shape_; }
  int rank() const { return static_cast<int>(shape_.size()); }
  int64_t dim(int i) const;  // negative counts from the end
  int64_t numel() const { return shape_numel(shape_); }
  size_t bytes() const { return static_cast<size_t>(numel()) * dtype_size(dtype_); }
  DType dtype() const { return dtype_; }
  Layout layout() const { return layout_; }
  bool empty() const { return data_ == nullptr; }

  void* data() { return data_; }
  const void* data() const { return data_; }
  // Typed access; throws std::logic_error on the wrong element type.
  float* f32();
  const float* f32() const;
  uint16_t* f16();
  const uint16_t* f16() const;

  // Same data, another shape of the same element count (a view; no copy).
  Tensor reshaped(const Shape& shape) const;
  // Deep copies, converting the element type.
  Tensor to_f32() const;
  Tensor to_f16() const;

 private:
  std::shared_ptr<void> owner_;
  void* data_ = nullptr;
  Shape shape_;
  DType dtype_ = DType::F32;
  Layout layout_ = Layout::Plain;
};

}  // namespace ampi
