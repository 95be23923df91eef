// The GEMM op (kernels/gemm.h) against the plain product (reference::gemm_direct) on
// every runnable ISA: sizes around the register tiles (4x8 scalar, 6x16 AVX2, 12x32
// AVX-512, 8x8 NEON) and vector widths, odd sizes, strided and transposed operands as an
// attention head sees them, bias, residual (apart and in place), every activation, B
// wider than a cache block; and bitwise equality across thread counts, between packed and
// strided B, and with Conv2d's pointwise path.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "kernel_sweeps.h"
#include "kernels/conv.h"
#include "kernels/gemm.h"
#include "kernels/reference/gemm_reference.h"

using namespace ampi;
using namespace ampi::test;

namespace {

// How B reaches the op.
enum class BForm { Packed, Strided, Transposed };

const char* form_name(BForm f) {
  switch (f) {
    case BForm::Packed: return "packed";
    case BForm::Strided: return "strided";
    case BForm::Transposed: return "transposed";
  }
  return "?";
}

struct GemmCase {
  int m = 1, n = 1, k = 1;
  // Extra floats at the end of each row of A, of B's memory and of C: strided views.
  int a_pad = 0, b_pad = 0, c_pad = 0;
  bool bias = true;
  enum class Residual { None, Apart, InPlace } residual = Residual::None;
  ActivationSpec act;
  uint32_t seed = 1;

  int64_t a_stride() const { return k + a_pad; }
  int64_t c_stride() const { return n + c_pad; }
};

std::string describe(const GemmCase& c) {
  std::ostringstream s;
  s << "m " << c.m << ", n " << c.n << ", k " << c.k << ", pads a" << c.a_pad << " b" << c.b_pad << " c" << c.c_pad
    << (c.bias ? ", bias" : "") << (c.residual == GemmCase::Residual::Apart     ? ", residual"
                                    : c.residual == GemmCase::Residual::InPlace ? ", residual in place"
                                                                                : "")
    << ", " << activation_name(c.act.kind) << ", seed " << c.seed;
  return s.str();
}

// The random operands of a case. B is held both ways round, so every form reads the
// same values: rows[kk][j] (k rows of n + b_pad) and columns[j][kk] (n rows of k + b_pad).
struct GemmData {
  std::vector<float> a, rows, columns, bias, residual;
  explicit GemmData(const GemmCase& c) {
    a = random_floats(static_cast<size_t>(c.m) * c.a_stride(), c.seed);
    rows = random_floats(static_cast<size_t>(c.k) * (c.n + c.b_pad), c.seed + 1);
    columns.assign(static_cast<size_t>(c.n) * (c.k + c.b_pad), 0.0f);
    for (int kk = 0; kk < c.k; ++kk)
      for (int j = 0; j < c.n; ++j)
        columns[static_cast<size_t>(j) * (c.k + c.b_pad) + kk] = rows[static_cast<size_t>(kk) * (c.n + c.b_pad) + j];
    if (c.bias) bias = random_floats(c.n, c.seed + 2);
    if (c.residual != GemmCase::Residual::None)
      residual = random_floats(static_cast<size_t>(c.m) * c.c_stride(), c.seed + 3, -4.0f, 4.0f);
  }
  const float* bias_or_null() const { return bias.empty() ? nullptr : bias.data(); }
  StridedMatrix view(const GemmCase& c, BForm form) const {
    if (form == BForm::Transposed) return {columns.data(), c.k + c.b_pad, true};
    return {rows.data(), c.n + c.b_pad, false};
  }
  // B^T as GemmWeights takes it: [n][k], no padding.
  std::vector<float> weights(const GemmCase& c) const {
    std::vector<float> w(static_cast<size_t>(c.n) * c.k);
    for (int j = 0; j < c.n; ++j)
      std::copy_n(columns.begin() + static_cast<int64_t>(j) * (c.k + c.b_pad), c.k, w.begin() + static_cast<int64_t>(j) * c.k);
    return w;
  }
};

// Values C's padding columns hold before and must hold after: the op writes n columns.
constexpr float kGapValue = -777.0f;

// The op's output as a GuardedOutput of m rows of c_stride floats: the n columns start as
// NaN (or the residual, when C is it), the padding as kGapValue.
GuardedOutput prepared_output(const GemmCase& c, const GemmData& d) {
  GuardedOutput out(static_cast<size_t>(c.m) * c.c_stride());
  for (int i = 0; i < c.m; ++i)
    for (int64_t j = 0; j < c.c_stride(); ++j) {
      const size_t at = static_cast<size_t>(i * c.c_stride() + j);
      if (j >= c.n) out.data()[at] = kGapValue;
      else if (c.residual == GemmCase::Residual::InPlace) out.data()[at] = d.residual[at];
    }
  return out;
}

GemmProblem problem(const GemmCase& c, const GemmData& d, GuardedOutput& out) {
  GemmProblem p;
  p.m = c.m, p.n = c.n, p.k = c.k;
  p.a = d.a.data();
  p.a_stride = c.a_stride();
  p.c = out.data();
  p.c_stride = c.c_stride();
  p.residual = c.residual == GemmCase::Residual::Apart ? d.residual.data()
               : c.residual == GemmCase::Residual::InPlace ? out.data()
                                                           : nullptr;
  p.act = c.act;
  return p;
}

// Runs the op on one table with B in one form; checks the guard and C's padding.
std::vector<float> run_gemm(const GemmCase& c, const GemmData& d, BForm form, const KernelTable& table,
                            ThreadPool& pool) {
  GuardedOutput out = prepared_output(c, d);
  const GemmProblem p = problem(c, d, out);
  if (form == BForm::Packed) {
    const std::vector<float> w = d.weights(c);
    gemm(p, GemmWeights(w.data(), d.bias_or_null(), c.n, c.k, table), pool);
  } else {
    gemm(p, d.view(c, form), d.bias_or_null(), pool, table);
  }
  CHECK(out.guard_intact());
  bool gaps_intact = true;
  for (int i = 0; i < c.m; ++i)
    for (int64_t j = c.n; j < c.c_stride(); ++j) gaps_intact &= out.data()[i * c.c_stride() + j] == kGapValue;
  CHECK(gaps_intact);
  return out.values();
}

struct Expected {
  std::vector<float> out;  // m rows of c_stride, the padding left as kGapValue
  float scale = 0.0f;      // kRelativeTolerance is relative to it
};

// The plain product without the epilogue, then the epilogue (as the convolution tests).
Expected expected_output(const GemmCase& c, const GemmData& d) {
  Expected e;
  e.out.assign(static_cast<size_t>(c.m) * c.c_stride(), kGapValue);
  GemmProblem linear;
  linear.m = c.m, linear.n = c.n, linear.k = c.k;
  linear.a = d.a.data();
  linear.a_stride = c.a_stride();
  linear.c = e.out.data();
  linear.c_stride = c.c_stride();
  reference::gemm_direct(linear, d.view(c, BForm::Strided), d.bias_or_null());
  float sums = 0.0f;
  for (int i = 0; i < c.m; ++i)
    for (int j = 0; j < c.n; ++j) sums = std::max(sums, std::fabs(e.out[i * c.c_stride() + j]));
  e.scale = std::max(1e-3f, sums + max_abs(d.residual));
  for (int i = 0; i < c.m; ++i)
    for (int j = 0; j < c.n; ++j) {
      float& v = e.out[i * c.c_stride() + j];
      v = ampi::activate(v, c.act) + (d.residual.empty() ? 0.0f : d.residual[i * c.c_stride() + j]);
    }
  return e;
}

float max_error(const Expected& e, const std::vector<float>& got) {
  return max_abs_diff(e.out.data(), got.data(), got.size());
}

// The op on every runnable table and every form of B against the plain product.
void check_all_isas(const GemmCase& c, ThreadPool& pool) {
  const GemmData d(c);
  const Expected e = expected_output(c, d);
  for (Isa isa : runnable_isas())
    for (BForm form : {BForm::Packed, BForm::Strided, BForm::Transposed}) {
      INFO(describe(c) << ", B " << form_name(form) << ", isa " << isa_name(isa) << ", threads " << pool.size());
      const std::vector<float> got = run_gemm(c, d, form, kernels_for(isa), pool);
      const float err = max_error(e, got);
      INFO("max error " << err << ", scale " << e.scale);
      REQUIRE(err <= kRelativeTolerance * e.scale);
    }
}

GemmCase sized(int m, int n, int k, uint32_t seed) {
  GemmCase c;
  c.m = m, c.n = n, c.k = k;
  c.seed = seed;
  return c;
}

}  // namespace

TEST_CASE("gemm matches the plain product over n and k around the panel and vector widths") {
  ThreadPool& pool = *thread_pools()[1];
  uint32_t seed = 100;
  // 13 rows: a partial tile for every ISA's tile height.
  for (int n : sweep<int>({1, 3, 4, 7, 8, 9, 15, 16, 17, 24, 31, 32, 33, 48, 63, 64, 65}, {1, 4, 7, 9, 17, 33}))
    for (int k : sweep<int>({1, 2, 3, 4, 7, 8, 9, 16, 17, 33, 64, 100}, {1, 3, 8, 17}))
      check_all_isas(sized(13, n, k, seed++), pool);
}

TEST_CASE("gemm matches the plain product for row counts around every tile height") {
  ThreadPool& pool = *thread_pools()[1];
  uint32_t seed = 1000;
  for (int m : sweep<int>({1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 17, 23, 24, 25, 37, 48, 49}, {1, 3, 5, 9, 13}))
    check_all_isas(sized(m, 33, 20, seed++), pool);
}

TEST_CASE("gemm with long reductions stays within tolerance") {
  ThreadPool& pool = *thread_pools()[1];
  check_all_isas(sized(7, 40, sweep<int>({1537}, {160}).front(), 2000), pool);
}

TEST_CASE("gemm on strided views: rows of A, B's memory and C longer than the product's") {
  ThreadPool& pool = *thread_pools()[1];
  uint32_t seed = 3000;
  for (int a_pad : {0, 1, 13})
    for (int b_pad : {0, 3, 16})
      for (int c_pad : {0, 5, 32}) {
        GemmCase c = sized(sweep<int>({29}, {9}).front(), 19, 21, seed++);
        c.a_pad = a_pad, c.b_pad = b_pad, c.c_pad = c_pad;
        c.residual = c_pad == 5 ? GemmCase::Residual::InPlace : GemmCase::Residual::Apart;
        check_all_isas(c, pool);
      }
}

// The kernels take a plain store path for no activation and no residual, and an epilogue
// path otherwise: both for every tile width (n = 40 ends in an 8-column panel, 21 and 13
// in the narrower AVX-512 tiles).
TEST_CASE("gemm with every activation, with and without bias and residual") {
  ThreadPool& pool = *thread_pools()[1];
  uint32_t seed = 4000;
  for (int n : {40, 21, 13})
    for (ActivationSpec act : all_activations())
      for (bool bias : {false, true})
        for (auto residual : {GemmCase::Residual::None, GemmCase::Residual::Apart, GemmCase::Residual::InPlace}) {
          GemmCase c = sized(17, n, 23, seed++);
          c.act = act;
          c.bias = bias;
          c.residual = residual;
          check_all_isas(c, pool);
        }
}

TEST_CASE("gemm across cache blocks of B and groups of rows of A matches the plain product") {
  ThreadPool& pool = *thread_pools()[1];
  const int k = 4096;  // long rows: blocks and groups are small
  for (Isa isa : runnable_isas()) {
    const KernelTable& table = kernels_for(isa);
    // Two whole blocks and groups, and a partial one of each.
    GemmCase c = sized(static_cast<int>(2 * gemm_group_rows(k, table.gemm_mr)) + 5,
                       2 * gemm_block_columns(k, table.gemm_nr) + 17, k, 5000);
    c.residual = GemmCase::Residual::Apart;
    c.act = {Activation::ReLU};
    const GemmData d(c);
    const Expected e = expected_output(c, d);
    for (BForm form : {BForm::Packed, BForm::Transposed}) {
      INFO(describe(c) << ", B " << form_name(form) << ", isa " << isa_name(isa));
      const float err = max_error(e, run_gemm(c, d, form, table, pool));
      INFO("max error " << err << ", scale " << e.scale);
      REQUIRE(err <= kRelativeTolerance * e.scale);
    }
  }
}

TEST_CASE("an attention head's two products on views of one [tokens][3 dim] buffer") {
  // Q K^T and P V per head without copies: Q, K and V are column ranges of each row.
  const int tokens = sweep<int>({37}, {11}).front(), heads = 3, head_dim = 8, dim = heads * head_dim;
  const std::vector<float> qkv = random_floats(static_cast<size_t>(tokens) * 3 * dim, 6000);
  const std::vector<float> probabilities = random_floats(static_cast<size_t>(tokens) * tokens, 6001, 0.0f, 1.0f);
  ThreadPool& pool = *thread_pools()[2];
  for (Isa isa : runnable_isas())
    for (int h = 0; h < heads; ++h) {
      INFO("isa " << isa_name(isa) << ", head " << h);
      const float* q = qkv.data() + h * head_dim;
      const float* k = q + dim;
      const float* v = q + 2 * dim;
      GemmProblem scores;
      scores.m = scores.n = tokens;
      scores.k = head_dim;
      scores.a = q;
      scores.a_stride = 3 * dim;
      std::vector<float> got(static_cast<size_t>(tokens) * tokens), want(got.size());
      scores.c = want.data();
      scores.c_stride = tokens;
      reference::gemm_direct(scores, {k, 3 * dim, true}, nullptr);
      scores.c = got.data();
      gemm(scores, {k, 3 * dim, true}, nullptr, pool, kernels_for(isa));
      CHECK(max_abs_diff(want.data(), got.data(), got.size()) <= kRelativeTolerance * 8.0f);

      // P V into the head's columns of a [tokens][dim] output.
      GemmProblem mix;
      mix.m = tokens, mix.n = head_dim, mix.k = tokens;
      mix.a = probabilities.data();
      mix.a_stride = tokens;
      mix.c_stride = dim;
      std::vector<float> mixed(static_cast<size_t>(tokens) * dim, kGapValue), mixed_want = mixed;
      mix.c = mixed_want.data() + h * head_dim;
      reference::gemm_direct(mix, {v, 3 * dim, false}, nullptr);
      mix.c = mixed.data() + h * head_dim;
      gemm(mix, {v, 3 * dim, false}, nullptr, pool, kernels_for(isa));
      CHECK(max_abs_diff(mixed_want.data(), mixed.data(), mixed.size()) <= kRelativeTolerance * tokens);
    }
}

TEST_CASE("gemm gives the same bits for any thread count and either form of B") {
  GemmCase c = sized(sweep<int>({203}, {41}).front(), 70, 50, 7000);
  c.residual = GemmCase::Residual::Apart;
  c.act = {Activation::HardSwish};
  const GemmData d(c);
  for (Isa isa : runnable_isas()) {
    INFO(describe(c) << ", isa " << isa_name(isa));
    const KernelTable& table = kernels_for(isa);
    const std::vector<float> first = run_gemm(c, d, BForm::Packed, table, *thread_pools()[0]);
    for (ThreadPool* pool : thread_pools())
      for (BForm form : {BForm::Packed, BForm::Strided, BForm::Transposed}) {
        INFO("B " << form_name(form) << ", threads " << pool->size());
        const std::vector<float> got = run_gemm(c, d, form, table, *pool);
        CHECK(std::memcmp(got.data(), first.data(), got.size() * sizeof(float)) == 0);
      }
  }
}

TEST_CASE("Conv2d's pointwise path is the GEMM op, bit for bit") {
  ConvParams p;
  p.in_c = 24;
  p.out_c = 40;
  p.act = {Activation::HardSwish};
  const int h = 9, w = 11, pixels = h * w;
  const auto in = random_floats(static_cast<size_t>(pixels) * p.in_c, 8000);
  const auto weights = random_floats(static_cast<size_t>(p.out_c) * p.in_c, 8001);
  const auto bias = random_floats(p.out_c, 8002);
  const auto residual = random_floats(static_cast<size_t>(pixels) * p.out_c, 8003);
  for (Isa isa : runnable_isas()) {
    INFO("isa " << isa_name(isa));
    const KernelTable& table = kernels_for(isa);
    std::vector<float> conv_out(residual.size()), gemm_out(residual.size());
    Conv2d(p, weights.data(), bias.data(), table).run(in.data(), h, w, conv_out.data(), residual.data(), *thread_pools()[1]);
    GemmProblem g;
    g.m = pixels, g.n = p.out_c, g.k = p.in_c;
    g.a = in.data();
    g.a_stride = p.in_c;
    g.c = gemm_out.data();
    g.c_stride = p.out_c;
    g.residual = residual.data();
    g.act = p.act;
    gemm(g, GemmWeights(weights.data(), bias.data(), p.out_c, p.in_c, table), *thread_pools()[2]);
    CHECK(std::memcmp(conv_out.data(), gemm_out.data(), conv_out.size() * sizeof(float)) == 0);
  }
}

TEST_CASE("gemm packs a strided B into the panels pack_gemm_weights makes") {
  const int n = 19, k = 5, nr = 8;
  const auto w = random_floats(static_cast<size_t>(n) * k, 9000);  // B^T, [n][k]
  const auto bias = random_floats(n, 9001);
  std::vector<float> from_weights(static_cast<size_t>(gemm_packed_size(n, k, nr)), -1.0f), from_view = from_weights;
  pack_gemm_weights(w.data(), bias.data(), n, k, nr, from_weights.data());
  std::vector<float> rows(static_cast<size_t>(k) * (n + 2));  // B row-major, 2 floats of padding
  for (int kk = 0; kk < k; ++kk)
    for (int j = 0; j < n; ++j) rows[static_cast<size_t>(kk) * (n + 2) + j] = w[static_cast<size_t>(j) * k + kk];
  // Panel by panel, in reverse: each lands in its own place.
  for (int panel = 2; panel >= 0; --panel)
    pack_gemm_panels({rows.data(), n + 2, false}, bias.data(), n, k, nr, panel, panel + 1, from_view.data());
  CHECK(from_view == from_weights);
}

TEST_CASE("gemm rejects sizes and strides that do not fit, and does nothing for no rows") {
  const std::vector<float> buffer(64, 1.0f);
  std::vector<float> out(64, 0.0f);
  GemmProblem p;
  p.m = 2, p.n = 4, p.k = 3;
  p.a = buffer.data();
  p.a_stride = 3;
  p.c = out.data();
  p.c_stride = 4;
  const StridedMatrix b{buffer.data(), 4, false};
  CHECK_NOTHROW(gemm(p, b, nullptr));
  const auto rejects = [&](GemmProblem q, StridedMatrix view, const char* message) {
    INFO(message);
    CHECK_THROWS_WITH(gemm(q, view, nullptr), Catch::Contains(message));
  };
  GemmProblem q = p;
  q.k = 0;
  rejects(q, b, "must be positive");
  q = p;
  q.a_stride = 2;
  rejects(q, b, "a_stride 2 is shorter than a row of A");
  q = p;
  q.c_stride = 3;
  rejects(q, b, "c_stride 3 is shorter than a row of C");
  rejects(p, {buffer.data(), 3, false}, "B's stride 3 is shorter than its rows");
  rejects(p, {buffer.data(), 2, true}, "B's stride 2 is shorter than its rows");
  rejects(p, {nullptr, 4, false}, "B is missing");
  q = p;
  q.a = nullptr;
  rejects(q, b, "A is missing");

  const GemmWeights weights(buffer.data(), nullptr, 4, 3);
  q = p;
  q.n = 5;
  q.c_stride = 5;
  CHECK_THROWS_WITH(gemm(q, weights), Catch::Contains("product with 3x4 weights"));
  CHECK_THROWS_WITH(GemmWeights(buffer.data(), nullptr, 0, 3), Catch::Contains("empty"));
  CHECK_THROWS_WITH(gemm(p, GemmWeights()), Catch::Contains("empty weights"));

  q = p;
  q.m = 0;
  q.a = nullptr;
  q.c = nullptr;
  CHECK_NOTHROW(gemm(q, b, nullptr));
  CHECK_NOTHROW(gemm(q, weights));
}
