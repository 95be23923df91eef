// Every convolution that is neither pointwise nor depthwise: the rows path (implicit
// GEMM on the input rows), the taps path of few-output convolutions and the general
// path (im2col + GEMM), each chosen by shape. Every kernel size, stride, padding,
// dilation and group count the networks use, every runnable ISA against the direct
// reference.
#include "conv_cases.h"

using namespace ampi;
using namespace ampi::test;

namespace {

ConvCase general(int in_c, int out_c, int kernel, int stride, int dilation, int groups, int h, int w,
                 uint32_t seed) {
  ConvCase c;
  c.p.in_c = in_c;
  c.p.out_c = out_c;
  c.p.kernel_h = c.p.kernel_w = kernel;
  c.p.stride_h = c.p.stride_w = stride;
  c.p.dilation_h = c.p.dilation_w = dilation;
  c.p.groups = groups;
  c.in_h = h;
  c.in_w = w;
  c.seed = seed;
  return c;
}

void set_padding(ConvCase& c, int top, int left, int bottom, int right) {
  c.p.pad_top = top;
  c.p.pad_left = left;
  c.p.pad_bottom = bottom;
  c.p.pad_right = right;
}

bool fits(const ConvCase& c) { return c.p.out_h(c.in_h) > 0 && c.p.out_w(c.in_w) > 0; }

}  // namespace

TEST_CASE("general conv matches the reference: kernels, strides, paddings, dilations, groups") {
  ThreadPool pool(2);
  struct Pad {
    int top, left, bottom, right;
  };
  const std::vector<Pad> pads = sweep<Pad>({{0, 0, 0, 0}, {1, 1, 1, 1}, {2, 2, 2, 2}, {1, 0, 2, 3}},
                                           {{1, 1, 1, 1}, {1, 0, 2, 3}});
  uint32_t seed = 7000;
  for (int kernel : sweep<int>({1, 3, 5, 7}, {1, 3, 5}))
    for (int stride : {1, 2})
      for (const Pad& pad : pads)
        for (int dilation : sweep<int>({1, 2, 4}, {1, 2}))
          for (int groups : {1, 2}) {
            ConvCase c = general(6, 10, kernel, stride, dilation, groups, 13, 15, seed++);
            set_padding(c, pad.top, pad.left, pad.bottom, pad.right);
            if (fits(c)) check_all_isas(c, pool);
          }
}

TEST_CASE("general 3x3 conv matches the reference over input and output channel counts") {
  ThreadPool pool(2);
  const std::vector<int> counts = sweep<int>({1, 3, 4, 8, 9, 16, 17, 32, 33}, {3, 9, 17});
  uint32_t seed = 8000;
  for (int in_c : counts)
    for (int out_c : counts) {
      ConvCase c = general(in_c, out_c, 3, 1, 1, 1, 7, 9, seed++);
      set_padding(c, 1, 1, 1, 1);
      check_all_isas(c, pool);
    }
}

TEST_CASE("general conv matches the reference for grouped and rectangular layers") {
  ThreadPool pool(2);
  uint32_t seed = 9000;
  SECTION("four groups, 33 outputs per group (more than one panel)") {
    ConvCase c = general(12, 132, 3, 1, 1, 4, 6, 7, seed++);
    set_padding(c, 1, 1, 1, 1);
    check_all_isas(c, pool);
  }
  SECTION("channel multiplier 2 (groups == in_c, out_c = 2 in_c)") {
    ConvCase c = general(9, 18, 3, 2, 1, 9, 9, 11, seed++);
    set_padding(c, 1, 1, 1, 1);
    check_all_isas(c, pool);
  }
  SECTION("1x1 with stride 2, and 1x1 with padding") {
    check_all_isas(general(16, 24, 1, 2, 1, 1, 9, 11, seed++), pool);
    ConvCase padded = general(16, 24, 1, 1, 1, 1, 5, 6, seed++);
    set_padding(padded, 1, 0, 0, 2);
    check_all_isas(padded, pool);
  }
  SECTION("1x7, 7x1 and 3x5 kernels with mixed strides and dilations") {
    ConvCase row = general(5, 11, 1, 1, 1, 1, 6, 17, seed++);
    row.p.kernel_w = 7;
    set_padding(row, 0, 3, 0, 3);
    check_all_isas(row, pool);
    ConvCase column = general(5, 11, 1, 1, 1, 1, 17, 6, seed++);
    column.p.kernel_h = 7;
    column.p.stride_h = 2;
    set_padding(column, 3, 0, 3, 0);
    check_all_isas(column, pool);
    ConvCase mixed = general(8, 12, 3, 1, 1, 2, 14, 19, seed++);
    mixed.p.kernel_w = 5;
    mixed.p.stride_w = 2;
    mixed.p.dilation_h = 2;
    set_padding(mixed, 2, 4, 1, 0);
    check_all_isas(mixed, pool);
  }
}

TEST_CASE("few-output conv (the taps path) matches the reference: channels, kernels, paddings, dilations") {
  ThreadPool pool(2);
  uint32_t seed = 9500;
  for (int out_c = 1; out_c <= 4; ++out_c)
    for (int in_c : sweep<int>({1, 3, 8, 16, 17, 33}, {3, 17}))
      for (int kernel : sweep<int>({3, 5}, {3}))
        for (int dilation : sweep<int>({1, 2}, {2})) {
          const int reach = (kernel - 1) * dilation;
          for (int pad_top : {0, reach / 2, reach}) {
            // Tall enough for several bands of rows on two threads.
            ConvCase c = general(in_c, out_c, kernel, 1, dilation, 1, sweep<int>({41}, {13}).front(), 11, seed++);
            set_padding(c, pad_top, reach - pad_top, reach / 2, reach / 2 + 1);
            c.p.kernel_w = kernel == 3 ? 5 : 3;
            if (fits(c)) check_all_isas(c, pool);
          }
        }
}

TEST_CASE("rows path (implicit GEMM) matches the reference: runs, strides, paddings, dilations") {
  ThreadPool pool(2);
  uint32_t seed = 9800;
  // in_c around the 16-float run threshold and the vector widths; out_c past one panel.
  for (int in_c : sweep<int>({2, 5, 6, 8, 12, 16, 17, 33}, {5, 16}))
    for (int out_c : sweep<int>({5, 16, 17, 40}, {17}))
      for (int kernel : sweep<int>({1, 3, 5}, {3}))
        for (int stride : {1, 2})
          for (int dilation : sweep<int>({1, 2}, {1, 2})) {
            const int reach = (kernel - 1) * dilation;
            ConvCase c = general(in_c, out_c, kernel, stride, dilation, 1, sweep<int>({29}, {11}).front(), 31, seed++);
            set_padding(c, reach / 2, reach - reach / 2, reach, reach / 2 + 1);
            if (!fits(c)) continue;
            const int run = dilation == 1 ? kernel * in_c : in_c;
            const bool winograd = kernel == 3 && stride == 1 && dilation == 1 && in_c >= 8;
            INFO(describe(c));
            CHECK(path_of(c) == (winograd ? Conv2d::Path::Winograd
                                          : run >= 16 ? Conv2d::Path::Rows : Conv2d::Path::General));
            check_all_isas(c, pool);
          }
  SECTION("padding wider than the kernel: rows and columns that read only zeros give the bias") {
    ConvCase c = general(7, 20, 3, 1, 1, 1, 6, 7, seed++);
    set_padding(c, 4, 4, 3, 5);
    c.residual = true;
    CHECK(path_of(c) == Conv2d::Path::Rows);
    check_all_isas(c, pool);
  }
  SECTION("no horizontal padding: A is read from the input rows themselves") {
    ConvCase c = general(7, 16, 3, 1, 1, 1, 9, 40, seed++);
    set_padding(c, 1, 0, 1, 0);
    CHECK(path_of(c) == Conv2d::Path::Rows);
    check_all_isas(c, pool);
  }
}
