// Winograd F(4x4, 3x3): the matrices of kernels/winograd.h compute a 3x3 correlation
// exactly (in exact arithmetic), every ISA's window and output transforms match the
// scalar reference, and Conv2d's winograd path matches the direct convolution over
// sizes (tiles cut by the map's edge, windows in the padding, several chunks), paddings,
// channel counts around every vector width and epilogues.
#include <cmath>

#include "conv_cases.h"
#include "kernels/reference/reference.h"
#include "kernels/winograd.h"

using namespace ampi;
using namespace ampi::test;

namespace {

using winograd::kPositions;
using winograd::kTile;
using winograd::kWindow;

ConvCase winograd_case(int in_c, int out_c, int h, int w, uint32_t seed) {
  ConvCase c;
  c.p.in_c = in_c;
  c.p.out_c = out_c;
  c.p.kernel_h = c.p.kernel_w = 3;
  c.p.pad_top = c.p.pad_left = c.p.pad_bottom = c.p.pad_right = 1;
  c.in_h = h;
  c.in_w = w;
  c.seed = seed;
  return c;
}

// How much a transform can magnify its inputs: (the largest row sum of |M|)^2 for a
// matrix applied along both axes. The kernels may round differently from the reference
// (another order of the same sums), by a few float ulps of that magnitude.
template <int kRows>
double gain(const double (&m)[kRows][kWindow]) {
  double most = 0.0;
  for (const auto& row : m) {
    double sum = 0.0;
    for (double x : row) sum += std::fabs(x);
    most = std::max(most, sum);
  }
  return most * most;
}
constexpr float kUlps = 1e-6f;

}  // namespace

TEST_CASE("the F(4x4, 3x3) matrices give a 3-tap correlation exactly") {
  // One axis is enough: the 2-D transform is the 1-D one along each axis. For every
  // window d and filter g of unit vectors, A^T [(G g) . (B^T d)] must be y[k] = sum_l
  // d[k + l] g[l].
  for (int d_at = 0; d_at < kWindow; ++d_at)
    for (int g_at = 0; g_at < 3; ++g_at)
      for (int k = 0; k < kTile; ++k) {
        double y = 0.0;
        for (int i = 0; i < kWindow; ++i)
          y += winograd::kOutputT[k][i] * winograd::kFilter[i][g_at] * winograd::kInputT[i][d_at];
        INFO("window tap " << d_at << ", filter tap " << g_at << ", output " << k);
        CHECK(std::fabs(y - (d_at == k + g_at ? 1.0 : 0.0)) < 1e-12);
      }
}

TEST_CASE("winograd_input matches the reference on every ISA") {
  uint32_t seed = 40000;
  for (int c : channel_sweep()) {
    const int64_t row_stride = (kWindow + 3) * int64_t{c};  // window rows inside a wider map
    const int64_t v_stride = c + 5;                           // positions further apart than c
    const std::vector<float> in = random_floats(size_t(kWindow) * row_stride, seed++, -4.0f, 4.0f);
    std::vector<float> expected(size_t(kPositions) * v_stride, 0.0f);
    reference::winograd_input(in.data(), row_stride, c, expected.data(), v_stride);
    const float tolerance = kUlps * float(gain(winograd::kInputT)) * max_abs(in);
    for (Isa isa : runnable_isas()) {
      INFO("channels " << c << ", isa " << isa_name(isa));
      std::vector<float> got(expected.size(), 0.0f);  // the gaps between positions stay 0
      kernels_for(isa).winograd_input(in.data(), row_stride, c, got.data(), v_stride);
      REQUIRE(max_abs_diff(expected.data(), got.data(), got.size()) <= tolerance);
    }
  }
}

TEST_CASE("winograd_output matches the reference on every ISA: epilogues and cut tiles") {
  uint32_t seed = 41000;
  for (int c : channel_sweep())
    for (ActivationSpec act : all_activations())
      for (bool residual : {false, true})
        for (int rows : {1, 3, 4})
          for (int cols : {1, 2, 4}) {
            WinogradOutputArgs o;
            o.m_stride = c + 3;
            o.channels = c;
            o.act = act;
            o.row_stride = (kTile + 2) * int64_t{c};
            o.rows = rows;
            o.cols = cols;
            const std::vector<float> m = random_floats(size_t(kPositions) * o.m_stride, seed++);
            const std::vector<float> bias = random_floats(c, seed++);
            const std::vector<float> res = random_floats(size_t(kTile) * o.row_stride, seed++);
            o.m = m.data();
            o.bias = bias.data();
            o.residual = residual ? res.data() : nullptr;
            const float tolerance = kUlps * (float(gain(winograd::kOutputT)) * max_abs(m) + max_abs(res));
            GuardedOutput expected(size_t(kTile) * o.row_stride);
            o.out = expected.data();
            reference::winograd_output(o);
            for (Isa isa : runnable_isas()) {
              INFO("channels " << c << ", " << activation_name(act.kind) << (residual ? ", residual" : "")
                               << ", tile " << rows << "x" << cols << ", isa " << isa_name(isa));
              GuardedOutput got(expected.size());
              o.out = got.data();
              kernels_for(isa).winograd_output(o);
              REQUIRE(got.guard_intact());
              // Outputs outside the tile's rows x cols stay unwritten (NaN) in both.
              const std::vector<float> e = expected.values(), g = got.values();
              for (size_t i = 0; i < e.size(); ++i) {
                if (std::isnan(e[i])) {
                  REQUIRE(std::isnan(g[i]));
                  continue;
                }
                REQUIRE(std::fabs(e[i] - g[i]) <= tolerance);
              }
            }
          }
}

TEST_CASE("winograd conv matches the direct convolution: sizes, paddings, channels") {
  ThreadPool pool(2);
  struct Pad {
    int top, left, bottom, right;
  };
  const std::vector<Pad> pads =
      sweep<Pad>({{1, 1, 1, 1}, {0, 0, 0, 0}, {1, 0, 2, 3}, {3, 2, 0, 1}}, {{1, 1, 1, 1}, {1, 0, 2, 3}});
  const std::vector<MapSize> sizes = sweep<MapSize>({{1, 1}, {2, 3}, {4, 4}, {5, 7}, {13, 9}, {29, 31}},
                                                    {{1, 1}, {5, 7}, {13, 9}});
  uint32_t seed = 42000;
  for (const MapSize& size : sizes)
    for (const Pad& pad : pads)
      for (int in_c : sweep<int>({8, 9, 16, 17, 33}, {8, 17}))
        for (int out_c : sweep<int>({5, 16, 17, 40}, {5, 17})) {
          ConvCase c = winograd_case(in_c, out_c, size.h, size.w, seed++);
          c.p.pad_top = pad.top;
          c.p.pad_left = pad.left;
          c.p.pad_bottom = pad.bottom;
          c.p.pad_right = pad.right;
          if (c.p.out_h(c.in_h) <= 0 || c.p.out_w(c.in_w) <= 0) continue;
          INFO(describe(c));
          REQUIRE(path_of(c) == Conv2d::Path::Winograd);
          check_all_isas(c, pool);
        }
}

TEST_CASE("winograd conv: many chunks, wide layers, every epilogue") {
  uint32_t seed = 43000;
  SECTION("64 -> 64 over 41 x 45: 132 tiles, several L2 chunks and a short last tile") {
    ThreadPool pool(2);
    ConvCase c = winograd_case(64, 64, 41, 45, seed++);
    c.residual = true;
    c.p.act = {Activation::ReLU};
    check_all_isas(c, pool);
  }
  SECTION("384 -> 64, the widest reduction of Depth Anything V2 ViT-S's head") {
    ThreadPool pool(2);
    check_all_isas(winograd_case(384, 64, 9, 11, seed++), pool);
  }
  SECTION("every activation, with and without the residual") {
    ThreadPool pool(2);
    for (ActivationSpec act : all_activations())
      for (bool residual : {false, true}) {
        ConvCase c = winograd_case(24, 19, 9, 10, seed++);
        c.p.act = act;
        c.residual = residual;
        check_all_isas(c, pool);
      }
  }
}
// 1, 2 and 3 threads giving the same bits: test_conv_api.cpp's case per path, the
// Winograd one over 110 tiles (several chunks).
