// Conv2d as the networks see it: the fused epilogue (every activation, residual), the
// path choice, results across thread counts, weight packing, and the errors.
#include "conv_cases.h"

using namespace ampi;
using namespace ampi::test;

namespace {

// One layer per path, with sizes that give several parallel chunks.
std::vector<ConvCase> one_case_per_path(uint32_t seed) {
  ConvCase pointwise;
  pointwise.p.in_c = 24;
  pointwise.p.out_c = 40;
  pointwise.in_h = 9;
  pointwise.in_w = 11;
  ConvCase depthwise;
  depthwise.p.in_c = depthwise.p.out_c = depthwise.p.groups = 33;
  depthwise.p.kernel_h = depthwise.p.kernel_w = 3;
  depthwise.p.pad_top = depthwise.p.pad_left = depthwise.p.pad_bottom = depthwise.p.pad_right = 1;
  depthwise.in_h = 9;
  depthwise.in_w = 21;
  ConvCase general = depthwise;
  general.p.in_c = 5;
  general.p.out_c = 19;
  general.p.groups = 1;
  ConvCase taps = general;
  taps.p.in_c = 24;
  taps.p.out_c = 4;
  ConvCase rows = general;
  rows.p.in_c = 7;
  rows.p.out_c = 19;
  ConvCase winograd = general;
  winograd.p.in_c = 12;
  winograd.p.out_c = 40;
  std::vector<ConvCase> cases = {pointwise, depthwise, general, taps, rows, winograd};
  for (ConvCase& c : cases) c.seed = seed++;
  return cases;
}

}  // namespace

TEST_CASE("every activation, with and without residual, on every path and ISA") {
  ThreadPool pool(2);
  uint32_t seed = 10000;
  for (ActivationSpec act : all_activations())
    for (bool residual : {false, true})
      for (ConvCase c : one_case_per_path(seed)) {
        seed += 3;
        c.p.act = act;
        c.residual = residual;
        check_all_isas(c, pool);
      }
}

TEST_CASE("results are bitwise identical for 1, 2 and 3 threads") {
  ThreadPool one(1), two(2), three(3);
  for (ConvCase c : one_case_per_path(11000)) {
    c.in_h = sweep<int>({37}, {13}).front();
    c.in_w = 41;
    c.residual = true;
    c.p.act = {Activation::HardSwish};
    const ConvData d(c);
    for (Isa isa : runnable_isas()) {
      INFO(describe(c) << ", isa " << isa_name(isa));
      const KernelTable& k = kernels_for(isa);
      const std::vector<float> single = run_conv(c, d, k, one);
      CHECK(run_conv(c, d, k, two) == single);
      CHECK(run_conv(c, d, k, three) == single);
    }
  }
  check_all_isas(one_case_per_path(11100)[0], three);
}

TEST_CASE("Conv2d picks the path by shape") {
  const std::vector<ConvCase> cases = one_case_per_path(12000);
  const auto path_of = [](const ConvParams& p) {
    const ConvData d(ConvCase{p, 8, 8, false, 1});
    return Conv2d(p, d.weights.data(), nullptr).path();
  };
  CHECK(path_of(cases[0].p) == Conv2d::Path::Pointwise);
  CHECK(path_of(cases[1].p) == Conv2d::Path::Depthwise);
  CHECK(path_of(cases[2].p) == Conv2d::Path::General);
  CHECK(path_of(cases[3].p) == Conv2d::Path::Taps);
  CHECK(path_of(cases[4].p) == Conv2d::Path::Rows);
  CHECK(path_of(cases[5].p) == Conv2d::Path::Winograd);
  ConvParams five_outputs = cases[3].p;
  five_outputs.out_c = 5;
  CHECK(path_of(five_outputs) == Conv2d::Path::Winograd);
  ConvParams strided_taps = cases[3].p;
  strided_taps.stride_h = 2;
  CHECK(path_of(strided_taps) == Conv2d::Path::Rows);
  // Winograd: 3x3, stride 1, no dilation, one group, from 8 inputs.
  ConvParams winograd = cases[5].p;
  winograd.in_c = 8;
  CHECK(path_of(winograd) == Conv2d::Path::Winograd);
  winograd.in_c = 7;
  CHECK(path_of(winograd) == Conv2d::Path::Rows);
  winograd.in_c = 12;
  winograd.dilation_h = 2;
  CHECK(path_of(winograd) == Conv2d::Path::Rows);
  winograd.dilation_h = 1;
  winograd.kernel_w = 5;
  CHECK(path_of(winograd) == Conv2d::Path::Rows);
  ConvParams grouped_taps = cases[3].p;
  grouped_taps.groups = 2;
  CHECK(path_of(grouped_taps) == Conv2d::Path::General);
  ConvParams strided = cases[0].p;
  strided.stride_w = 2;
  CHECK(path_of(strided) == Conv2d::Path::Rows);
  // A run is kernel_w * in_c floats, or in_c when the taps are dilated across the row:
  // under 16, im2col's copies cost less than reloading the output tile per run.
  ConvParams dilated = cases[4].p;
  dilated.dilation_w = 2;
  CHECK(path_of(dilated) == Conv2d::Path::General);
  dilated.in_c = 16;
  CHECK(path_of(dilated) == Conv2d::Path::Rows);
  ConvParams multiplier = cases[1].p;
  multiplier.out_c = 66;
  CHECK(path_of(multiplier) == Conv2d::Path::General);
}

TEST_CASE("a missing bias counts as zero") {
  for (ConvCase c : one_case_per_path(13000)) {
    const ConvData d(c);
    ConvData zero_bias = d;
    std::fill(zero_bias.bias.begin(), zero_bias.bias.end(), 0.0f);
    for (Isa isa : runnable_isas()) {
      INFO(describe(c) << ", isa " << isa_name(isa));
      ThreadPool pool(1);
      const Conv2d conv(c.p, d.weights.data(), nullptr, kernels_for(isa));
      std::vector<float> got(run_conv(c, zero_bias, kernels_for(isa), pool).size());
      conv.run(d.in.data(), c.in_h, c.in_w, got.data(), nullptr, pool);
      CHECK(got == run_conv(c, zero_bias, kernels_for(isa), pool));
    }
  }
}

TEST_CASE("the direct reference applies the epilogue after the sum") {
  ConvCase c = one_case_per_path(14000)[2];
  c.p.act = {Activation::ELU, 0.5f};
  c.residual = true;
  const ConvData d(c);
  const Expected e = expected_output(c, d);
  std::vector<float> direct(e.out.size());
  reference::conv2d_direct(c.p, d.in.data(), c.in_h, c.in_w, d.weights.data(), d.bias.data(),
                           d.residual.data(), direct.data());
  CHECK(direct == e.out);
}

TEST_CASE("pack_gemm_weights lays out panels of bias then k rows, zero padded") {
  // n = 3 filters of k = 2 weights, panels 2 wide: two panels.
  const float b[] = {1, 2, 3, 4, 5, 6};
  const float bias[] = {10, 20, 30};
  REQUIRE(gemm_packed_size(3, 2, 2) == 12);
  std::vector<float> packed(12, -1.0f);
  pack_gemm_weights(b, bias, 3, 2, 2, packed.data());
  CHECK(packed == std::vector<float>{10, 20, 1, 3, 2, 4, 30, 0, 5, 0, 6, 0});
}

TEST_CASE("output size follows the convolution arithmetic") {
  ConvParams p;
  p.in_c = p.out_c = 1;
  p.kernel_h = 3;
  p.kernel_w = 5;
  p.stride_h = 2;
  p.pad_top = 1;
  p.pad_bottom = 1;
  p.dilation_w = 2;
  CHECK(p.out_h(7) == 4);   // (7 + 2 - 2 - 1) / 2 + 1
  CHECK(p.out_h(1) == 1);
  CHECK(p.out_w(9) == 1);   // 9 - 8 - 1 = 0 -> 1
  CHECK(p.out_w(8) == 0);   // the dilated kernel (9 wide) does not fit
  CHECK(p.out_w(1) == 0);
}

TEST_CASE("invalid layers and inputs are rejected with a message") {
  ConvParams good;
  good.in_c = 4;
  good.out_c = 6;
  good.kernel_h = good.kernel_w = 3;
  const std::vector<float> w(6 * 9 * 4, 0.5f);
  const auto rejects = [&](ConvParams p, const char* message) {
    INFO(message);
    CHECK_THROWS_WITH(Conv2d(p, w.data(), nullptr), Catch::Contains(message));
  };
  ConvParams p = good;
  p.in_c = 0;
  rejects(p, "in_c must be positive");
  p = good;
  p.stride_w = 0;
  rejects(p, "stride_w must be positive");
  p = good;
  p.dilation_h = -1;
  rejects(p, "dilation_h must be positive");
  p = good;
  p.pad_left = -1;
  rejects(p, "padding must not be negative");
  p = good;
  p.groups = 3;
  rejects(p, "groups 3 does not divide in_c 4");
  p = good;
  p.groups = 4;
  rejects(p, "groups 4 does not divide out_c 6");
  CHECK_THROWS_WITH(Conv2d(good, nullptr, nullptr), Catch::Contains("weights are missing"));

  const Conv2d conv(good, w.data(), nullptr);
  std::vector<float> in(2 * 5 * 4), out(64);
  CHECK_THROWS_WITH(conv.run(in.data(), 2, 5, out.data()),
                    Catch::Contains("input 2x5 is smaller than the dilated 3x3 kernel"));
  CHECK_THROWS_WITH(conv.run(in.data(), 0, 5, out.data()), Catch::Contains("empty"));
  CHECK_THROWS_WITH(Conv2d().run(in.data(), 2, 5, out.data()), Catch::Contains("empty Conv2d"));
}
