// The vision transformer's ops (kernels/transformer_ops.h) against plain double-precision
// references written out here, for every runnable ISA and thread count, over sizes that
// cross the vector widths, the GEMM tiles and the attention's query and key blocks.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "kernels/transformer_ops.h"
#include "kernel_sweeps.h"
#include "support/random.h"

using namespace ampi;

namespace {

float max_abs(const std::vector<float>& v) {
  float m = 0;
  for (float x : v) m = std::max(m, std::fabs(x));
  return m;
}

// out[i][j] = sum_k m[i][k] in[k][j] for one axis of a bicubic resize, as a dense matrix.
std::vector<double> cubic_matrix(int n_out, int n_in, double src_per_dst) {
  const double a = -0.75;
  const auto near = [a](double t) { return ((a + 2) * t - (a + 3)) * t * t + 1; };
  const auto far = [a](double t) { return ((a * t - 5 * a) * t + 8 * a) * t - 4 * a; };
  std::vector<double> m(size_t(n_out) * n_in, 0.0);
  for (int i = 0; i < n_out; ++i) {
    const double src = (i + 0.5) * src_per_dst - 0.5, base = std::floor(src), t = src - base;
    const double w[4] = {far(t + 1), near(t), near(1 - t), far(2 - t)};
    for (int tap = 0; tap < 4; ++tap) {
      const int k = std::min(std::max(int(base) - 1 + tap, 0), n_in - 1);
      m[size_t(i) * n_in + k] += w[tap];
    }
  }
  return m;
}

std::vector<float> bicubic_reference(const std::vector<float>& in, int h, int w, int c, int oh, int ow, double sy,
                                     double sx) {
  const std::vector<double> my = cubic_matrix(oh, h, sy), mx = cubic_matrix(ow, w, sx);
  std::vector<float> out(size_t(oh) * ow * c);
  for (int y = 0; y < oh; ++y)
    for (int x = 0; x < ow; ++x)
      for (int ch = 0; ch < c; ++ch) {
        double s = 0;
        for (int i = 0; i < h; ++i)
          for (int j = 0; j < w; ++j) s += my[size_t(y) * h + i] * mx[size_t(x) * w + j] * in[(size_t(i) * w + j) * c + ch];
        out[(size_t(y) * ow + x) * c + ch] = float(s);
      }
  return out;
}

std::vector<float> bilinear_corners_reference(const std::vector<float>& in, int h, int w, int c, int oh, int ow) {
  std::vector<float> out(size_t(oh) * ow * c);
  const auto source = [](int i, int n_in, int n_out) { return n_out > 1 ? double(i) * (n_in - 1) / (n_out - 1) : 0.0; };
  for (int y = 0; y < oh; ++y)
    for (int x = 0; x < ow; ++x) {
      const double sy = source(y, h, oh), sx = source(x, w, ow);
      const int y0 = std::min(int(sy), h - 1), x0 = std::min(int(sx), w - 1);
      const int y1 = std::min(y0 + 1, h - 1), x1 = std::min(x0 + 1, w - 1);
      const double fy = sy - y0, fx = sx - x0;
      for (int ch = 0; ch < c; ++ch) {
        const auto at = [&](int yy, int xx) { return double(in[(size_t(yy) * w + xx) * c + ch]); };
        const double top = at(y0, x0) * (1 - fx) + at(y0, x1) * fx, bottom = at(y1, x0) * (1 - fx) + at(y1, x1) * fx;
        out[(size_t(y) * ow + x) * c + ch] = float(top * (1 - fy) + bottom * fy);
      }
    }
  return out;
}

// softmax(scale q k^T) v per head, the whole score row at once, in double.
std::vector<float> attention_reference(const std::vector<float>& qkv, int tokens, int dim, int heads, float scale) {
  const int hd = dim / heads;
  std::vector<float> out(size_t(tokens) * dim);
  std::vector<double> p(tokens);
  for (int h = 0; h < heads; ++h)
    for (int i = 0; i < tokens; ++i) {
      double top = -INFINITY, sum = 0;
      for (int j = 0; j < tokens; ++j) {
        double s = 0;
        for (int d = 0; d < hd; ++d)
          s += double(qkv[size_t(i) * 3 * dim + h * hd + d]) * qkv[size_t(j) * 3 * dim + dim + h * hd + d];
        p[j] = s * scale;
        top = std::max(top, p[j]);
      }
      for (int j = 0; j < tokens; ++j) sum += p[j] = std::exp(p[j] - top);
      for (int d = 0; d < hd; ++d) {
        double acc = 0;
        for (int j = 0; j < tokens; ++j) acc += p[j] * qkv[size_t(j) * 3 * dim + 2 * dim + h * hd + d];
        out[size_t(i) * dim + h * hd + d] = float(acc / sum);
      }
    }
  return out;
}

}  // namespace

TEST_CASE("cubic_axis: a unit step is the identity, and every row's weights sum to 1") {
  const CubicAxis same = cubic_axis(7, 7, 1.0);
  for (int i = 0; i < 7; ++i) {
    float at_i = 0, total = 0;
    for (int tap = 0; tap < 4; ++tap) {
      total += same.weight[i * 4 + tap];
      if (same.index[i * 4 + tap] == i) at_i += same.weight[i * 4 + tap];
    }
    CHECK(at_i == 1.0f);
    CHECK(total == 1.0f);
  }
  const CubicAxis down = cubic_axis(5, 13, 13.0 / 5.0);
  for (int i = 0; i < 5; ++i) {
    double total = 0;
    for (int tap = 0; tap < 4; ++tap) {
      total += down.weight[i * 4 + tap];
      CHECK(down.index[i * 4 + tap] >= 0);
      CHECK(down.index[i * 4 + tap] < 13);
    }
    CHECK(total == Approx(1.0).margin(1e-6));
  }
}

TEST_CASE("resize_bicubic matches the dense separable reference, up and down, any steps") {
  struct Case { int h, w, c, oh, ow; double sy, sx; };
  const std::vector<Case> cases = test::sweep<Case>(
      {{4, 4, 16, 5, 7, 4 / 5.1, 4 / 7.1}, {3, 5, 3, 7, 2, 3.0 / 7, 5.0 / 2}, {9, 6, 1, 4, 13, 9.0 / 4, 6.0 / 13},
       {1, 1, 5, 2, 3, 0.5, 1.0 / 3}, {6, 6, 17, 6, 6, 1.0, 1.0}},
      {{4, 4, 16, 5, 7, 4 / 5.1, 4 / 7.1}, {3, 5, 3, 7, 2, 3.0 / 7, 5.0 / 2}});
  for (ThreadPool* pool : test::thread_pools())
    for (const Case& k : cases) {
      const uint32_t seed = uint32_t(100 * k.h + 10 * k.w + k.c);
      INFO("threads " << pool->size() << ", " << k.h << "x" << k.w << "x" << k.c << " -> " << k.oh << "x" << k.ow
                      << ", seed " << seed);
      const std::vector<float> in = test::random_floats(size_t(k.h) * k.w * k.c, seed);
      const std::vector<float> expected = bicubic_reference(in, k.h, k.w, k.c, k.oh, k.ow, k.sy, k.sx);
      test::GuardedOutput got(expected.size());
      resize_bicubic(in.data(), k.h, k.w, k.c, k.oh, k.ow, k.sy, k.sx, got.data(), *pool);
      CHECK(test::max_abs_diff(expected.data(), got.data(), expected.size()) <= 5e-6f);
      CHECK(got.guard_intact());
    }
}

TEST_CASE("interpolate_pos_embed keeps the class token and resizes the grid with the offset scale") {
  const int grid = 4, dim = 9, rows = 5, cols = 7;
  const double offset = 0.1;
  const std::vector<float> pos = test::random_floats(size_t(1 + grid * grid) * dim, 5);
  const std::vector<float> got = interpolate_pos_embed(pos.data(), grid, dim, rows, cols, offset);
  REQUIRE(got.size() == size_t(1 + rows * cols) * dim);
  for (int j = 0; j < dim; ++j) CHECK(got[j] == pos[j]);
  const std::vector<float> grid_values(pos.begin() + dim, pos.end());
  const std::vector<float> expected =
      bicubic_reference(grid_values, grid, grid, dim, rows, cols, grid / (rows + offset), grid / (cols + offset));
  CHECK(test::max_abs_diff(expected.data(), got.data() + dim, expected.size()) <= 5e-6f);
  // The pretrained grid itself is copied, not resampled.
  CHECK(interpolate_pos_embed(pos.data(), grid, dim, grid, grid, offset) == pos);
}

TEST_CASE("resize_bilinear_corners matches the align_corners formula on every ISA") {
  struct Case { int h, w, oh, ow; };
  const std::vector<Case> sizes = test::sweep<Case>(
      {{1, 1, 3, 4}, {2, 3, 5, 9}, {5, 7, 5, 7}, {9, 6, 4, 13}, {4, 4, 56, 70}, {7, 5, 1, 1}},
      {{2, 3, 5, 9}, {9, 6, 4, 13}});
  for (Isa isa : runnable_isas())
    for (ThreadPool* pool : test::thread_pools())
      for (int c : test::channel_sweep())
        for (const Case& k : sizes) {
          const uint32_t seed = uint32_t(1000 * c + 10 * k.h + k.w);
          INFO("isa " << isa_name(isa) << ", threads " << pool->size() << ", c " << c << ", " << k.h << "x" << k.w
                      << " -> " << k.oh << "x" << k.ow << ", seed " << seed);
          const std::vector<float> in = test::random_floats(size_t(k.h) * k.w * c, seed);
          const std::vector<float> expected = bilinear_corners_reference(in, k.h, k.w, c, k.oh, k.ow);
          test::GuardedOutput got(expected.size());
          resize_bilinear_corners(in.data(), k.h, k.w, c, k.oh, k.ow, got.data(), *pool, kernels_for(isa));
          CHECK(test::max_abs_diff(expected.data(), got.data(), expected.size()) <= 1e-6f);
          CHECK(got.guard_intact());
        }
}

TEST_CASE("resize_bilinear_corners_rows gives exactly those rows of the whole resize") {
  ThreadPool pool(2);
  const int h = 7, w = 5, c = 9, oh = 23, ow = 11;
  const std::vector<float> in = test::random_floats(size_t(h) * w * c, 1234);
  std::vector<float> whole(size_t(oh) * ow * c);
  resize_bilinear_corners(in.data(), h, w, c, oh, ow, whole.data(), pool);
  for (int begin : {0, 1, 6, 22})
    for (int end : {begin + 1, std::min(oh, begin + 4), oh}) {
      INFO("rows " << begin << ".." << end);
      test::GuardedOutput got(size_t(end - begin) * ow * c);
      resize_bilinear_corners_rows(in.data(), h, w, c, oh, ow, begin, end, got.data(), pool);
      CHECK(got.values() == std::vector<float>(whole.begin() + size_t(begin) * ow * c, whole.begin() + size_t(end) * ow * c));
      CHECK(got.guard_intact());
    }
  std::vector<float> out(size_t(oh) * ow * c);
  for (auto [begin, end] : {std::pair{-1, 3}, {3, 3}, {5, 2}, {0, oh + 1}})
    CHECK_THROWS_WITH(resize_bilinear_corners_rows(in.data(), h, w, c, oh, ow, begin, end, out.data(), pool),
                      Catch::Contains("are not inside 0..23"));
}

TEST_CASE("layer_norm over strided tokens matches the double reference on every ISA") {
  for (Isa isa : runnable_isas())
    for (ThreadPool* pool : test::thread_pools())
      for (int c : test::channel_sweep()) {
        const int tokens = 37, stride = c + 3;
        const uint32_t seed = uint32_t(77 + c);
        INFO("isa " << isa_name(isa) << ", threads " << pool->size() << ", c " << c << ", seed " << seed);
        const std::vector<float> in = test::random_floats(size_t(tokens) * stride, seed, -3.0f, 5.0f);
        const std::vector<float> gamma = test::random_floats(c, seed + 1), beta = test::random_floats(c, seed + 2);
        std::vector<float> expected(size_t(tokens) * c);
        for (int t = 0; t < tokens; ++t) {
          double mean = 0, var = 0;
          for (int j = 0; j < c; ++j) mean += in[size_t(t) * stride + j];
          mean /= c;
          for (int j = 0; j < c; ++j) var += std::pow(in[size_t(t) * stride + j] - mean, 2);
          var /= c;
          for (int j = 0; j < c; ++j)
            expected[size_t(t) * c + j] =
                float((in[size_t(t) * stride + j] - mean) / std::sqrt(var + 1e-6) * gamma[j] + beta[j]);
        }
        test::GuardedOutput got(expected.size());
        layer_norm(in.data(), stride, tokens, c, gamma.data(), beta.data(), 1e-6f, got.data(), c, *pool,
                   kernels_for(isa));
        CHECK(test::max_abs_diff(expected.data(), got.data(), expected.size()) <= 2e-5f);
        CHECK(got.guard_intact());
      }
}

TEST_CASE("self_attention streamed over key blocks equals softmax attention, on every ISA") {
  struct Case { int tokens, dim, heads; };
  // Token counts below, at and across the 96-query and 1,536-key blocks (three blocks of
  // keys at 3,100); head widths around the vector widths.
  const std::vector<Case> cases = test::sweep<Case>(
      {{1, 8, 1}, {5, 12, 3}, {96, 16, 2}, {97, 34, 2}, {300, 51, 3}, {1537, 16, 1}, {3100, 8, 1}},
      {{5, 12, 3}, {97, 34, 2}, {1537, 8, 1}});
  for (Isa isa : runnable_isas())
    for (ThreadPool* pool : test::thread_pools())
      for (const Case& k : cases) {
        const uint32_t seed = uint32_t(10 * k.tokens + k.dim);
        INFO("isa " << isa_name(isa) << ", threads " << pool->size() << ", tokens " << k.tokens << ", dim " << k.dim
                    << ", heads " << k.heads << ", seed " << seed);
        const std::vector<float> qkv = test::random_floats(size_t(k.tokens) * 3 * k.dim, seed);
        const float scale = 1.0f / std::sqrt(float(k.dim / k.heads));
        const std::vector<float> expected = attention_reference(qkv, k.tokens, k.dim, k.heads, scale);
        const int stride = k.dim + 5;  // the output may be a column band of a wider buffer
        std::vector<float> got(size_t(k.tokens) * stride, NAN);
        self_attention(qkv.data(), k.tokens, k.dim, k.heads, scale, got.data(), stride, *pool, kernels_for(isa));
        float err = 0;
        for (int t = 0; t < k.tokens; ++t)
          err = std::max(err, test::max_abs_diff(&expected[size_t(t) * k.dim], &got[size_t(t) * stride], k.dim));
        CHECK(err <= 2e-5f * std::max(1.0f, max_abs(expected)));
      }
}

TEST_CASE("PatchEmbedding equals a direct strided convolution plus the residual") {
  for (Isa isa : runnable_isas())
    for (ThreadPool* pool : test::thread_pools())
      for (int dim : test::sweep<int>({1, 8, 17, 33}, {8, 17})) {
        const int patch = 3, rows = 2, cols = 5, h = rows * patch, w = cols * patch, k = patch * patch * 3;
        const uint32_t seed = uint32_t(300 + dim);
        INFO("isa " << isa_name(isa) << ", threads " << pool->size() << ", dim " << dim << ", seed " << seed);
        const std::vector<float> image = test::random_floats(size_t(h) * w * 3, seed);
        const std::vector<float> weights = test::random_floats(size_t(dim) * k, seed + 1);
        const std::vector<float> bias = test::random_floats(dim, seed + 2);
        const int stride = dim + 2;
        const std::vector<float> residual = test::random_floats(size_t(rows) * cols * stride, seed + 3);
        std::vector<float> expected(size_t(rows) * cols * stride, 0.0f);
        for (int r = 0; r < rows; ++r)
          for (int c = 0; c < cols; ++c)
            for (int o = 0; o < dim; ++o) {
              double s = bias[o];
              for (int ky = 0; ky < patch; ++ky)
                for (int kx = 0; kx < patch; ++kx)
                  for (int ch = 0; ch < 3; ++ch)
                    s += double(weights[((size_t(o) * patch + ky) * patch + kx) * 3 + ch]) *
                         image[((size_t(r) * patch + ky) * w + c * patch + kx) * 3 + ch];
              const size_t at = (size_t(r) * cols + c) * stride + o;
              expected[at] = float(s + residual[at]);
            }
        std::vector<float> got(expected.size(), 0.0f);
        PatchEmbedding embed(patch, dim, weights.data(), bias.data(), kernels_for(isa));
        embed.run(image.data(), h, w, got.data(), stride, residual.data(), *pool);
        CHECK(test::max_abs_diff(expected.data(), got.data(), got.size()) <= 1e-5f);
      }
  PatchEmbedding embed(14, 4, std::vector<float>(14 * 14 * 3 * 4).data(), nullptr);
  std::vector<float> image(20 * 28 * 3), out(100);
  CHECK_THROWS_WITH(embed.run(image.data(), 20, 28, out.data(), 4, nullptr),
                    Catch::Contains("not a multiple of the patch size 14"));
}

TEST_CASE("StridedTransposedConv (kernel = stride) equals the direct transposed convolution") {
  for (Isa isa : runnable_isas())
    for (ThreadPool* pool : test::thread_pools())
      for (int s : {2, 4})
        for (int c : test::sweep<int>({1, 3, 8, 9, 17}, {3, 9})) {
          const int h = 3, w = 5, in_c = c + 2, out_c = c;
          const uint32_t seed = uint32_t(500 + 10 * s + c);
          INFO("isa " << isa_name(isa) << ", threads " << pool->size() << ", stride " << s << ", in " << in_c
                      << ", out " << out_c << ", seed " << seed);
          const std::vector<float> in = test::random_floats(size_t(h) * w * in_c, seed);
          const std::vector<float> weights = test::random_floats(size_t(s) * s * out_c * in_c, seed + 1);
          const std::vector<float> bias = test::random_floats(out_c, seed + 2);
          const int oh = h * s, ow = w * s;
          std::vector<float> expected(size_t(oh) * ow * out_c);
          for (int y = 0; y < oh; ++y)
            for (int x = 0; x < ow; ++x)
              for (int o = 0; o < out_c; ++o) {
                double acc = bias[o];
                const int ky = y % s, kx = x % s;
                for (int i = 0; i < in_c; ++i)
                  acc += double(in[(size_t(y / s) * w + x / s) * in_c + i]) *
                         weights[((size_t(ky) * s + kx) * out_c + o) * in_c + i];
                expected[(size_t(y) * ow + x) * out_c + o] = float(acc);
              }
          test::GuardedOutput got(expected.size());
          StridedTransposedConv up(s, in_c, out_c, weights.data(), bias.data(), kernels_for(isa));
          up.run(in.data(), h, w, got.data(), *pool);
          CHECK(test::max_abs_diff(expected.data(), got.data(), expected.size()) <= 1e-5f);
          CHECK(got.guard_intact());
        }
}
