#include "engine/tensor.h"

#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>

#include "engine/half.h"

namespace ampi {

size_t dtype_size(DType dtype) { return dtype == DType::F32 ? 4 : 2; }
const char* dtype_name(DType dtype) { return dtype == DType::F32 ? "f32" : "f16"; }

int64_t shape_numel(const Shape& shape) {
  int64_t n = 1;
  for (int64_t d : shape) n *= d;
  return n;
}

std::string shape_str(const Shape& shape) {
  std::string s = "[";
  for (size_t i = 0; i < shape.size(); ++i) {
    if (i) s += ", ";
    s += std::to_string(shape[i]);
  }
  return s + "]";
}

void AlignedDeleter::operator()(void* p) const { std::free(p); }

AlignedBuffer aligned_alloc64(size_t bytes) {
  const size_t rounded = (bytes + 63) / 64 * 64;
  void* p = std::aligned_alloc(64, rounded == 0 ? 64 : rounded);
  if (!p) throw std::bad_alloc();
  return AlignedBuffer(p);
}

static void check_shape(const Shape& shape) {
  for (int64_t d : shape)
    if (d < 0) throw std::invalid_argument("negative dimension in shape " + shape_str(shape));
}

Tensor Tensor::empty(const Shape& shape, DType dtype, Layout layout) {
  check_shape(shape);
  Tensor t;
  t.shape_ = shape;
  t.dtype_ = dtype;
  t.layout_ = layout;
  AlignedBuffer buffer = aligned_alloc64(t.bytes());
  t.data_ = buffer.get();
  t.owner_ = std::shared_ptr<void>(buffer.release(), AlignedDeleter());
  return t;
}

Tensor Tensor::zeros(const Shape& shape, DType dtype, Layout layout) {
  Tensor t = empty(shape, dtype, layout);
  std::memset(t.data_, 0, t.bytes());
  return t;
}

Tensor Tensor::view(void* data, const Shape& shape, DType dtype, Layout layout) {
  check_shape(shape);
  Tensor t;
  t.data_ = data;
  t.shape_ = shape;
  t.dtype_ = dtype;
  t.layout_ = layout;
  return t;
}

int64_t Tensor::dim(int i) const {
  const int r = rank();
  if (i < 0) i += r;
  if (i < 0 || i >= r) throw std::out_of_range("tensor has no dimension " + std::to_string(i));
  return shape_[i];
}

float* Tensor::f32() {
  if (dtype_ != DType::F32) throw std::logic_error("tensor holds f16, not f32");
  return static_cast<float*>(data_);
}
const float* Tensor::f32() const { return const_cast<Tensor*>(this)->f32(); }
uint16_t* Tensor::f16() {
  if (dtype_ != DType::F16) throw std::logic_error("tensor holds f32, not f16");
  return static_cast<uint16_t*>(data_);
}
const uint16_t* Tensor::f16() const { return const_cast<Tensor*>(this)->f16(); }

Tensor Tensor::reshaped(const Shape& shape) const {
  if (shape_numel(shape) != numel())
    throw std::invalid_argument("cannot reshape " + shape_str(shape_) + " to " + shape_str(shape));
  Tensor t = *this;
  t.shape_ = shape;
  return t;
}

Tensor Tensor::to_f32() const {
  Tensor out = empty(shape_, DType::F32, layout_);
  const int64_t n = numel();
  if (dtype_ == DType::F32) {
    std::memcpy(out.data_, data_, bytes());
  } else {
    const uint16_t* src = f16();
    for (int64_t i = 0; i < n; ++i) out.f32()[i] = half_to_float(src[i]);
  }
  return out;
}

Tensor Tensor::to_f16() const {
  Tensor out = empty(shape_, DType::F16, layout_);
  const int64_t n = numel();
  if (dtype_ == DType::F16) {
    std::memcpy(out.data_, data_, bytes());
  } else {
    const float* src = f32();
    for (int64_t i = 0; i < n; ++i) out.f16()[i] = float_to_half(src[i]);
  }
  return out;
}

}  // namespace ampi
