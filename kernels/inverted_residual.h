// A MobileNetV3 inverted residual without squeeze-excite, run as one op:
//   out = project(depthwise(expand(in))) (+ residual)
//
// The expanded tensors are the widest of the block (3-6x its input). At high resolution
// they fit in no cache, so run layer by layer each is written to memory and read back,
// and the block is bound by memory bandwidth. Here each task owns a tile of output rows
// and columns and keeps in cache only a ring of expanded rows (as many as the depthwise
// kernel spans) and one depthwise row: an expanded row is computed once per tile that
// reads it, so only the rows at the tile seams are computed twice.
//
// Every value comes from the same micro-kernels, on the same inputs, in the same order as
// the three Conv2d::run calls, so the output is bitwise identical to running them one after
// the other, on every table and thread count (tests/kernels/test_inverted_residual.cpp).
// Squeeze-excite needs the whole depthwise output before the projection, so blocks with
// it keep the three separate steps.
#pragma once
#include <optional>

#include "engine/thread_pool.h"
#include "kernels/conv.h"

namespace ampi {

class InvertedResidual {
 public:
  // expand: a pointwise Conv2d, or none when the block has no expansion (the depthwise
  // then reads the input itself); dw: depthwise, stride 1, 'same' padding (the output has
  // the input's size); project: pointwise. All three packed for the same table. Throws
  // std::invalid_argument when they do not chain that way.
  InvertedResidual(std::optional<Conv2d> expand, Conv2d dw, Conv2d project);

  // in: NHWC [h][w][in_c]; out: [h][w][out_c]; residual: nullptr or the shape of out.
  // in and out never alias.
  void run(const float* in, int h, int w, float* out, const float* residual,
           ThreadPool& pool = default_pool()) const;

  // The same on the channel concatenation of two maps (a decoder's upsampled map and its
  // skip connection): pixel p's input is first[p] (first_c floats) then second[p]
  // (second_c floats), first_c + second_c = in_c, without the concatenated map ever
  // being written: each tile concatenates the rows it expands, in cache. add_input: the
  // residual is the (concatenated) input itself (in_c == out_c). Needs an expansion.
  // Bitwise run() on the concatenated map.
  void run_concat(const float* first, int first_c, const float* second, int second_c, int h, int w,
                  float* out, bool add_input, ThreadPool& pool = default_pool()) const;

 private:
  struct Tile {
    int y0, y1, x0, x1;
  };
  // The block's input: one map (second == nullptr), or two concatenated by channel.
  struct Input {
    const float* first;
    int first_c;
    const float* second = nullptr;
    int second_c = 0;
  };
  struct Scratch;  // one thread's ring of expanded rows, depthwise row and input rows
  void run_input(const Input& in, int h, int w, float* out, const float* residual, bool add_input,
                 ThreadPool& pool) const;
  void run_tile(const Tile& t, const Input& in, int h, int w, float* out, const float* residual,
                bool add_input, int ring_w, Scratch& s) const;

  std::optional<Conv2d> expand_;
  Conv2d dw_, project_;
  int in_c_ = 0, expanded_ = 0, out_c_ = 0;
};

}  // namespace ampi
