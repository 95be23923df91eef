// Pointwise (1x1) convolution: the packed GEMM path, every runnable ISA against the
// direct reference.
#include "conv_cases.h"

#include "engine/tensor.h"

using namespace ampi;
using namespace ampi::test;

namespace {

// Below, at and above each vector width (NEON 4, AVX2 8, AVX-512 16) and panel width
// (8, 16, 32), and multiples of them.
std::vector<int> channel_counts() {
  return sweep<int>({1, 3, 4, 7, 8, 9, 15, 16, 17, 24, 31, 32, 33, 48, 64, 96}, {1, 4, 7, 9, 17, 33});
}

ConvCase pointwise(int in_c, int out_c, int h, int w, uint32_t seed) {
  ConvCase c;
  c.p.in_c = in_c;
  c.p.out_c = out_c;
  c.in_h = h;
  c.in_w = w;
  c.seed = seed;
  return c;
}

}  // namespace

TEST_CASE("pointwise conv matches the reference over input and output channel counts") {
  ThreadPool pool(2);
  uint32_t seed = 1000;
  for (int in_c : channel_counts())
    for (int out_c : channel_counts()) check_all_isas(pointwise(in_c, out_c, 5, 7, seed++), pool);
}

TEST_CASE("pointwise conv matches the reference for pixel counts around every row tile") {
  // 1 to 91 pixels: partial and whole tiles of 4, 6, 8 and 12 rows.
  ThreadPool pool(2);
  uint32_t seed = 2000;
  for (int h : sweep<int>({1, 2, 3, 5, 7}, {1, 3}))
    for (int w : sweep<int>({1, 2, 3, 5, 7, 13}, {1, 5, 13})) check_all_isas(pointwise(17, 33, h, w, seed++), pool);
}

TEST_CASE("pointwise conv with long reductions stays within tolerance") {
  ThreadPool pool(2);
  check_all_isas(pointwise(sweep<int>({576}, {160}).front(), 40, 3, 5, 3000), pool);
}

namespace {

// A 1x1 case through one table's gemm tile, called directly (Conv2d streams only outputs
// larger than the last-level cache), into a 64-byte-aligned output as
// GemmArgs::stream_c requires.
std::vector<float> run_gemm_tiles(const ConvCase& c, const ConvData& d, const KernelTable& k,
                                  bool stream_c) {
  const int n = c.p.out_c, kdim = c.p.in_c, pixels = c.in_h * c.in_w;
  std::vector<float> packed(static_cast<size_t>(gemm_packed_size(n, kdim, k.gemm_nr)));
  pack_gemm_weights(d.weights.data(), d.bias.data(), n, kdim, k.gemm_nr, packed.data());
  Tensor out = Tensor::empty({pixels, n});
  std::fill(out.f32(), out.f32() + out.numel(), NAN);  // an unwritten value cannot pass
  GemmArgs g;
  g.n = n;
  g.k = kdim;
  g.a_stride = kdim;
  g.packed = packed.data();
  g.c_stride = n;
  g.act = c.p.act;
  g.stream_c = stream_c;
  for (int row = 0; row < pixels; row += k.gemm_mr) {
    g.m = std::min(k.gemm_mr, pixels - row);
    g.a = d.in.data() + static_cast<int64_t>(row) * kdim;
    g.c = out.f32() + static_cast<int64_t>(row) * n;
    g.residual = d.residual.empty() ? nullptr : d.residual.data() + static_cast<int64_t>(row) * n;
    k.gemm(g);
  }
  return std::vector<float>(out.f32(), out.f32() + out.numel());
}

}  // namespace

TEST_CASE("gemm tiles with streaming stores match plain stores and the reference") {
  uint32_t seed = 3000;
  for (int out_c : {16, 32, 48, 64})
    for (bool residual : {false, true}) {
      ConvCase c = pointwise(24, out_c, 5, 7, seed++);  // 35 pixels: whole and partial row tiles
      c.p.act = {residual ? Activation::ReLU : Activation::HardSwish};
      c.residual = residual;
      check_streaming_all_isas(c, run_gemm_tiles);
    }
}

TEST_CASE("pointwise conv with a scaled input equals the conv of the scaled input") {
  ThreadPool pool(2);
  uint32_t seed = 3500;
  for (int in_c : sweep<int>({1, 7, 16, 33, 96}, {7, 33}))
    for (int out_c : sweep<int>({4, 24, 40, 64}, {24, 40})) {
      ConvCase c = pointwise(in_c, out_c, 5, 7, seed);
      c.p.act = {Activation::HardSwish};
      c.residual = true;
      ConvData d(c);
      const std::vector<float> scale = random_floats(in_c, seed++, 0.0f, 1.0f);
      ConvData scaled = d;
      for (size_t i = 0; i < scaled.in.size(); ++i) scaled.in[i] *= scale[i % in_c];
      const Expected e = expected_output(c, scaled);
      for (Isa isa : runnable_isas()) {
        INFO(describe(c) << ", isa " << isa_name(isa));
        const Conv2d conv(c.p, d.weights.data(), d.bias.data(), kernels_for(isa));
        GuardedOutput out(e.out.size());
        conv.run_scaled_input(d.in.data(), c.in_h, c.in_w, scale.data(), out.data(), d.residual.data(), pool);
        CHECK(out.guard_intact());
        const float err = max_abs_diff(e.out.data(), out.data(), e.out.size());
        INFO("max error " << err << ", scale " << e.scale);
        REQUIRE(err <= kRelativeTolerance * e.scale);
      }
    }
  ConvCase general = pointwise(4, 4, 5, 5, seed);
  general.p.kernel_h = general.p.kernel_w = 3;
  const ConvData d(general);
  const Conv2d conv(general.p, d.weights.data(), d.bias.data());
  std::vector<float> out(5 * 5 * 4), scale(4, 1.0f);
  CHECK_THROWS_AS(conv.run_scaled_input(d.in.data(), 5, 5, scale.data(), out.data()), std::runtime_error);
}
