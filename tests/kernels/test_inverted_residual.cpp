// The fused inverted residual (kernels/inverted_residual.h) against its own definition:
// the three Conv2d::run calls one after the other, bit for bit, on every runnable table and
// thread count, over channel counts around the vector widths, odd sizes, kernel sizes,
// dilations and paddings, and sizes wide and tall enough to split into several tiles.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "kernel_sweeps.h"
#include "kernels/conv.h"
#include "kernels/inverted_residual.h"
#include "support/random.h"

using namespace ampi;
using namespace ampi::test;

namespace {

struct BlockCase {
  int in_c, expanded, out_c;  // expanded == in_c: no expansion
  int kernel, dilation;
  int pad_top, pad_left;      // the bottom and right pads make the output the input's size
  int h, w;
  bool residual;
  uint32_t seed;
};

std::string describe(const BlockCase& b) {
  std::ostringstream s;
  s << "in " << b.h << "x" << b.w << "x" << b.in_c << ", expanded " << b.expanded << ", out "
    << b.out_c << ", kernel " << b.kernel << ", dilation " << b.dilation << ", pad t" << b.pad_top
    << " l" << b.pad_left << (b.residual ? ", residual" : "") << ", seed " << b.seed;
  return s.str();
}

ConvParams conv_params(int in_c, int out_c, int kernel, int groups, Activation act) {
  ConvParams p;
  p.in_c = in_c;
  p.out_c = out_c;
  p.kernel_h = p.kernel_w = kernel;
  p.groups = groups;
  p.act = {act};
  return p;
}

struct Layers {
  std::optional<Conv2d> expand;
  Conv2d dw, project;
};

Layers make_layers(const BlockCase& b, const KernelTable& k) {
  uint32_t seed = b.seed;
  const auto conv = [&](ConvParams p) {
    const auto w = random_floats(size_t(p.out_c) * p.kernel_h * p.kernel_w * (p.in_c / p.groups), seed++);
    const auto bias = random_floats(p.out_c, seed++);
    return Conv2d(p, w.data(), bias.data(), k);
  };
  Layers l;
  if (b.expanded != b.in_c) l.expand = conv(conv_params(b.in_c, b.expanded, 1, 1, Activation::ReLU));
  ConvParams dw = conv_params(b.expanded, b.expanded, b.kernel, b.expanded, Activation::HardSwish);
  dw.dilation_h = dw.dilation_w = b.dilation;
  dw.pad_top = b.pad_top;
  dw.pad_left = b.pad_left;
  dw.pad_bottom = (b.kernel - 1) * b.dilation - b.pad_top;
  dw.pad_right = (b.kernel - 1) * b.dilation - b.pad_left;
  l.dw = conv(dw);
  l.project = conv(conv_params(b.expanded, b.out_c, 1, 1, Activation::None));
  return l;
}

// Both ways on one table and pool; the fused output starts as NaN, so a value it never
// writes fails the comparison.
void check_fused_equals_steps(const BlockCase& b, const KernelTable& k, ThreadPool& pool) {
  const Layers l = make_layers(b, k);
  const size_t pixels = size_t(b.h) * b.w;
  const auto in = random_floats(pixels * b.in_c, b.seed + 100);
  const auto residual = random_floats(pixels * b.out_c, b.seed + 101, -4.0f, 4.0f);
  const float* res = b.residual ? residual.data() : nullptr;

  std::vector<float> expanded(pixels * b.expanded), dw_out(pixels * b.expanded), steps(pixels * b.out_c);
  if (l.expand) l.expand->run(in.data(), b.h, b.w, expanded.data(), nullptr, pool);
  l.dw.run(l.expand ? expanded.data() : in.data(), b.h, b.w, dw_out.data(), nullptr, pool);
  l.project.run(dw_out.data(), b.h, b.w, steps.data(), res, pool);

  const InvertedResidual fused(l.expand, l.dw, l.project);
  GuardedOutput out(pixels * b.out_c);
  fused.run(in.data(), b.h, b.w, out.data(), res, pool);
  INFO(describe(b) << ", isa " << isa_name(k.isa) << ", threads " << pool.size());
  REQUIRE(out.guard_intact());
  REQUIRE(std::equal(steps.begin(), steps.end(), out.data(),
                     [](float x, float y) { return std::memcmp(&x, &y, sizeof x) == 0; }));
}

void check_everywhere(const BlockCase& b) {
  for (Isa isa : runnable_isas())
    for (ThreadPool* pool : thread_pools()) check_fused_equals_steps(b, kernels_for(isa), *pool);
}

}  // namespace

TEST_CASE("fused inverted residual equals its three convolutions over channel counts") {
  uint32_t seed = 1;
  for (int in_c : sweep<int>({3, 8, 16, 17}, {3, 17}))
    for (int expanded : sweep<int>({4, 15, 16, 33, 64}, {4, 33}))
      for (int out_c : sweep<int>({1, 8, 24, 33}, {8, 33}))
        check_everywhere({in_c, expanded, out_c, 3, 1, 1, 1, 7, 9, in_c == out_c, seed++});
}

TEST_CASE("fused inverted residual equals its three convolutions without an expansion") {
  for (int c : sweep<int>({1, 4, 16, 24}, {4, 17}))
    check_everywhere({c, c, c, 3, 1, 1, 1, 6, 11, true, 200u + c});
}

TEST_CASE("fused inverted residual equals its three convolutions over kernels, dilations, paddings") {
  uint32_t seed = 300;
  for (int kernel : {1, 3, 5})
    for (int dilation : sweep<int>({1, 2, 3}, {1, 2})) {
      const int reach = (kernel - 1) * dilation;
      for (int pad_top : {0, reach / 2, reach})
        check_everywhere({8, 24, 8, kernel, dilation, pad_top, reach - pad_top, 9, 13, true, seed++});
    }
}

TEST_CASE("fused inverted residual equals its three convolutions when it splits into tiles") {
  // 96 expanded channels: a strip is about 170 columns, so 400 columns make three strips;
  // 1 to 3 threads make 8 to 24 tiles, so bands of a few rows.
  check_everywhere({24, 96, 24, 3, 1, 1, 1, sweep<int>({37}, {9}).front(), 400, true, 400});
  check_everywhere({16, 64, 24, 5, 1, 2, 2, sweep<int>({29}, {7}).front(), 300, false, 401});
  for (int h : {1, 2, 3}) check_everywhere({8, 16, 8, 3, 1, 1, 1, h, 5, true, 410u + h});
}

TEST_CASE("fused inverted residual rejects convolutions that do not chain") {
  const KernelTable& k = kernels();
  const auto make = [&](ConvParams p) {
    const std::vector<float> w(size_t(p.out_c) * p.kernel_h * p.kernel_w * (p.in_c / p.groups), 0.5f);
    return Conv2d(p, w.data(), nullptr, k);
  };
  const Conv2d expand = make(conv_params(8, 16, 1, 1, Activation::ReLU));
  ConvParams dwp = conv_params(16, 16, 3, 16, Activation::ReLU);
  dwp.pad_top = dwp.pad_left = dwp.pad_bottom = dwp.pad_right = 1;
  const Conv2d dw = make(dwp), project = make(conv_params(16, 8, 1, 1, Activation::None));
  CHECK_NOTHROW(InvertedResidual(expand, dw, project));
  ConvParams strided = dwp;
  strided.stride_h = strided.stride_w = 2;
  CHECK_THROWS_AS(InvertedResidual(expand, make(strided), project), std::invalid_argument);
  ConvParams shrinking = dwp;
  shrinking.pad_bottom = 0;
  CHECK_THROWS_AS(InvertedResidual(expand, make(shrinking), project), std::invalid_argument);
  CHECK_THROWS_AS(InvertedResidual(expand, dw, make(conv_params(12, 8, 1, 1, Activation::None))),
                  std::invalid_argument);
  CHECK_THROWS_AS(InvertedResidual(make(conv_params(8, 12, 1, 1, Activation::ReLU)), dw, project),
                  std::invalid_argument);
  CHECK_THROWS_AS(InvertedResidual(expand, project, project), std::invalid_argument);
}

TEST_CASE("fused inverted residual on two concatenated maps equals it on their concatenation") {
  for (const int first_c : sweep<int>({1, 8, 16}, {8}))
    for (const int second_c : sweep<int>({7, 16}, {16}))
      for (const bool add_input : {false, true}) {
        const int in_c = first_c + second_c, h = 9, w = 300;  // several strips and bands
        const BlockCase b{in_c, 4 * in_c, add_input ? in_c : 24, 3, 1, 1, 1, h, w, add_input,
                          uint32_t(500 + 10 * first_c + second_c)};
        for (Isa isa : runnable_isas())
          for (ThreadPool* pool : thread_pools()) {
            const KernelTable& k = kernels_for(isa);
            const Layers l = make_layers(b, k);
            const InvertedResidual fused(l.expand, l.dw, l.project);
            const size_t pixels = size_t(h) * w;
            const auto first = random_floats(pixels * first_c, b.seed + 100);
            const auto second = random_floats(pixels * second_c, b.seed + 101);
            std::vector<float> joined(pixels * in_c), expected(pixels * b.out_c);
            k.concat_channels(first.data(), first_c, second.data(), second_c, int64_t(pixels), joined.data());
            fused.run(joined.data(), h, w, expected.data(), add_input ? joined.data() : nullptr, *pool);
            GuardedOutput out(pixels * b.out_c);
            fused.run_concat(first.data(), first_c, second.data(), second_c, h, w, out.data(), add_input, *pool);
            INFO(describe(b) << ", split " << first_c << " + " << second_c << ", isa " << isa_name(isa)
                             << ", threads " << pool->size());
            REQUIRE(out.guard_intact());
            REQUIRE(std::equal(expected.begin(), expected.end(), out.data(),
                               [](float x, float y) { return std::memcmp(&x, &y, sizeof x) == 0; }));
          }
      }
}

TEST_CASE("fused inverted residual rejects a concatenation that does not fit it") {
  const BlockCase b{24, 96, 24, 3, 1, 1, 1, 4, 4, true, 600};
  const Layers l = make_layers(b, kernels());
  const InvertedResidual fused(l.expand, l.dw, l.project);
  const std::vector<float> in(16 * 24, 0.5f);
  std::vector<float> out(16 * 24);
  CHECK_THROWS_AS(fused.run_concat(in.data(), 8, in.data(), 8, 4, 4, out.data(), false), std::invalid_argument);
  CHECK_THROWS_AS(fused.run_concat(in.data(), 0, in.data(), 24, 4, 4, out.data(), false), std::invalid_argument);
  const BlockCase plain{16, 16, 16, 3, 1, 1, 1, 4, 4, true, 601};  // no expansion
  const Layers p = make_layers(plain, kernels());
  const InvertedResidual unexpanded(p.expand, p.dw, p.project);
  CHECK_THROWS_AS(unexpanded.run_concat(in.data(), 8, in.data(), 8, 4, 4, out.data(), true), std::invalid_argument);
  const BlockCase widening{24, 96, 32, 3, 1, 1, 1, 4, 4, false, 602};
  const Layers wl = make_layers(widening, kernels());
  const InvertedResidual widens(wl.expand, wl.dw, wl.project);
  CHECK_THROWS_AS(widens.run_concat(in.data(), 8, in.data(), 16, 4, 4, out.data(), true), std::invalid_argument);
}
