// Depthwise convolution (groups == in_c == out_c): the row kernels, every runnable ISA
// against the direct reference.
#include "test_conv_util.h"

using namespace ampi;
using namespace ampi::test;

namespace {

struct Padding {
  int top, left, bottom, right;
};

ConvCase depthwise(int channels, int kernel, int stride, int dilation, Padding pad, int h, int w,
                   uint32_t seed) {
  ConvCase c;
  c.p.in_c = c.p.out_c = c.p.groups = channels;
  c.p.kernel_h = c.p.kernel_w = kernel;
  c.p.stride_h = c.p.stride_w = stride;
  c.p.dilation_h = c.p.dilation_w = dilation;
  c.p.pad_top = pad.top;
  c.p.pad_left = pad.left;
  c.p.pad_bottom = pad.bottom;
  c.p.pad_right = pad.right;
  c.in_h = h;
  c.in_w = w;
  c.seed = seed;
  return c;
}

Padding same_padding(int kernel, int dilation) {
  const int p = dilation * (kernel - 1) / 2;
  return {p, p, p, p};
}

bool fits(const ConvCase& c) { return c.p.out_h(c.in_h) > 0 && c.p.out_w(c.in_w) > 0; }

}  // namespace

TEST_CASE("depthwise conv matches the reference: kernels, strides, dilations, paddings, channels") {
  ThreadPool pool(2);
  const std::vector<Padding> paddings = {{0, 0, 0, 0}, {1, 1, 1, 1}, {2, 2, 2, 2}, {0, 2, 1, 0}};
  const std::vector<int> channels =
      sweep<int>({1, 3, 4, 7, 8, 9, 15, 16, 17, 24, 31, 32, 33, 48}, {3, 4, 9, 17});
  uint32_t seed = 4000;
  for (int kernel : {3, 5})
    for (int stride : {1, 2})
      for (int dilation : sweep<int>({1, 2, 4}, {1, 2}))
        for (const Padding& pad : sweep<Padding>(paddings, {{1, 1, 1, 1}, {0, 2, 1, 0}}))
          for (int c : channels) {
            // 27 columns leave whole blocks of 8 interior pixels beside the borders.
            const ConvCase conv = depthwise(c, kernel, stride, dilation, pad, 11, 27, seed++);
            if (fits(conv)) check_all_isas(conv, pool);
          }
}

TEST_CASE("depthwise conv matches the reference on small and odd input sizes") {
  ThreadPool pool(2);
  uint32_t seed = 5000;
  for (int kernel : {3, 5})
    for (int stride : {1, 2})
      for (int h : sweep<int>({1, 2, 3, 5, 7, 13}, {1, 3, 7}))
        for (int w : sweep<int>({1, 2, 3, 5, 7, 13}, {2, 5, 13}))
          check_all_isas(depthwise(17, kernel, stride, 1, same_padding(kernel, 1), h, w, seed++), pool);
}

TEST_CASE("depthwise conv matches the reference for other kernel shapes") {
  ThreadPool pool(2);
  uint32_t seed = 6000;
  for (int kernel : {1, 7}) check_all_isas(depthwise(19, kernel, 1, 1, same_padding(kernel, 1), 9, 23, seed++), pool);
  ConvCase wide = depthwise(20, 3, 1, 1, {1, 2, 1, 2}, 8, 25, seed++);
  wide.p.kernel_w = 5;
  wide.p.stride_h = 2;
  wide.p.dilation_h = 2;
  check_all_isas(wide, pool);
}
