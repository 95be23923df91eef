// The numpy fixtures (tests/fixtures/make_fixtures.py): every case of
// tests/fixtures/ops/cases.txt, run through the op layer with every runnable ISA and
// thread count, must reproduce numpy's float64 result to float32 precision.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "kernels/conv.h"
#include "kernels/ops.h"
#include "kernel_sweeps.h"
#include "weights_format/npy.h"

using namespace ampi;

namespace {

const std::string kFixtureDir = std::string(AMPI_SOURCE_DIR) + "/tests/fixtures/ops/";

// One line of cases.txt: `NAME OP key=value ...`.
struct FixtureCase {
  std::string name, op;
  std::map<std::string, std::string> params;

  const std::string& param(const std::string& key) const {
    const auto it = params.find(key);
    if (it == params.end()) throw std::runtime_error(name + ": no parameter '" + key + "'");
    return it->second;
  }
  int integer(const std::string& key) const { return std::stoi(param(key)); }
  ActivationSpec activation() const {
    return {parse_activation(param("act").c_str()), std::stof(param("alpha"))};
  }
  Tensor array(const std::string& role) const { return read_npy(kFixtureDir + name + "." + role + ".npy"); }
};

std::vector<FixtureCase> read_cases() {
  const std::string path = kFixtureDir + "cases.txt";
  std::ifstream file(path);
  if (!file) throw std::runtime_error(path + ": cannot open (run tests/fixtures/make_fixtures.py)");
  std::vector<FixtureCase> cases;
  std::string line;
  for (int number = 1; std::getline(file, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    FixtureCase c;
    if (!(fields >> c.name >> c.op))
      throw std::runtime_error(path + ":" + std::to_string(number) + ": expected NAME OP");
    for (std::string kv; fields >> kv;) {
      const size_t eq = kv.find('=');
      if (eq == std::string::npos)
        throw std::runtime_error(path + ":" + std::to_string(number) + ": '" + kv + "' is not key=value");
      c.params[kv.substr(0, eq)] = kv.substr(eq + 1);
    }
    cases.push_back(c);
  }
  return cases;
}

int dim(const Tensor& t, int i) { return static_cast<int>(t.dim(i)); }

// Runs a case's op on its fixture input with one table and pool; returns the output.
using Runner = std::function<std::vector<float>(const FixtureCase&, ThreadPool&, const KernelTable&)>;

std::vector<float> run_conv2d(const FixtureCase& c, ThreadPool& pool, const KernelTable& k) {
  const Tensor in = c.array("input"), weight = c.array("weight"), bias = c.array("bias");
  ConvParams p;
  p.in_c = dim(in, 2);
  p.out_c = dim(weight, 0);
  p.kernel_h = c.integer("kh");
  p.kernel_w = c.integer("kw");
  p.stride_h = c.integer("sh");
  p.stride_w = c.integer("sw");
  p.pad_top = c.integer("pt");
  p.pad_left = c.integer("pl");
  p.pad_bottom = c.integer("pb");
  p.pad_right = c.integer("pr");
  p.dilation_h = c.integer("dh");
  p.dilation_w = c.integer("dw");
  p.groups = c.integer("groups");
  p.act = c.activation();
  const Tensor residual = c.integer("residual") ? c.array("residual") : Tensor();
  const Conv2d conv(p, weight.f32(), bias.f32(), k);
  std::vector<float> out(static_cast<size_t>(p.out_h(dim(in, 0))) * p.out_w(dim(in, 1)) * p.out_c);
  conv.run(in.f32(), dim(in, 0), dim(in, 1), out.data(), residual.empty() ? nullptr : residual.f32(), pool);
  return out;
}

std::vector<float> run_squeeze_excite(const FixtureCase& c, ThreadPool& pool, const KernelTable& k) {
  const Tensor in = c.array("input");
  const SqueezeExcite se(dim(in, 2), c.integer("reduced"), c.array("w1").f32(), c.array("b1").f32(),
                         c.array("w2").f32(), c.array("b2").f32(), k);
  std::vector<float> out(in.numel());
  se.run(in.f32(), dim(in, 0), dim(in, 1), out.data(), pool);
  return out;
}

// haar_dwt, haar_idwt and the resizes take [h][w][c'] and the channel count c' / divisor
// (the IDWT is given its output channels); the resizes write 4 values per input value,
// the DWT and its inverse as many as they read.
Runner resample_runner(void (*op)(const float*, int, int, int, float*, ThreadPool&, const KernelTable&),
                       int channel_divisor, int growth) {
  return [=](const FixtureCase& c, ThreadPool& pool, const KernelTable& k) {
    const Tensor in = c.array("input");
    std::vector<float> out(in.numel() * growth);
    op(in.f32(), dim(in, 0), dim(in, 1), dim(in, 2) / channel_divisor, out.data(), pool, k);
    return out;
  };
}

std::vector<float> run_concat(const FixtureCase& c, ThreadPool& pool, const KernelTable& k) {
  const Tensor a = c.array("input"), b = c.array("other");
  std::vector<float> out(a.numel() + b.numel());
  concat_channels(a.f32(), dim(a, 2), b.f32(), dim(b, 2), a.numel() / dim(a, 2), out.data(), pool, k);
  return out;
}

std::vector<float> run_add(const FixtureCase& c, ThreadPool& pool, const KernelTable& k) {
  const Tensor a = c.array("input"), b = c.array("other");
  std::vector<float> out(a.numel());
  add(a.f32(), b.f32(), a.numel(), out.data(), c.activation(), pool, k);
  return out;
}

std::vector<float> run_gated_output(const FixtureCase& c, ThreadPool& pool, const KernelTable& k) {
  const Tensor in = c.array("input");
  const int channels = dim(in, 2) / 2;
  std::vector<float> out(in.numel() / 2);
  gated_output(in.f32(), in.numel() / dim(in, 2), channels, c.activation(), out.data(), pool, k);
  return out;
}

std::vector<float> run_activate(const FixtureCase& c, ThreadPool& pool, const KernelTable& k) {
  const Tensor in = c.array("input");
  std::vector<float> out(in.f32(), in.f32() + in.numel());
  activate(out.data(), static_cast<int64_t>(out.size()), c.activation(), pool, k);
  return out;
}

const std::map<std::string, Runner>& runners() {
  static const std::map<std::string, Runner> table = {
      {"conv2d", run_conv2d},
      {"squeeze_excite", run_squeeze_excite},
      {"haar_dwt", resample_runner(haar_dwt, 1, 1)},
      {"haar_idwt", resample_runner(haar_idwt, 4, 1)},
      {"resize2x_nearest", resample_runner(resize2x_nearest, 1, 4)},
      {"resize2x_bilinear", resample_runner(resize2x_bilinear, 1, 4)},
      {"concat", run_concat},
      {"add", run_add},
      {"gated_output", run_gated_output},
      {"activate", run_activate},
  };
  return table;
}

// Largest error in units of max(1, |expected|): float32 rounding of sums of a few dozen
// terms stays near 1e-6 of that.
float max_scaled_error(const Tensor& expected, const std::vector<float>& got) {
  float worst = 0.0f;
  for (size_t i = 0; i < got.size(); ++i) {
    const float e = expected.f32()[i];
    const float err = std::fabs(got[i] - e) / std::max(1.0f, std::fabs(e));
    if (std::isnan(err)) return INFINITY;
    worst = std::max(worst, err);
  }
  return worst;
}

}  // namespace

TEST_CASE("numpy fixtures: every ISA and thread count reproduces every case") {
  const std::vector<FixtureCase> cases = read_cases();
  std::map<std::string, int> per_op;
  for (const FixtureCase& c : cases) {
    INFO("case " << c.name << " (" << c.op << ")");
    const auto runner = runners().find(c.op);
    REQUIRE(runner != runners().end());
    ++per_op[c.op];
    const Tensor expected = c.array("expected");
    for (Isa isa : runnable_isas())
      for (ThreadPool* pool : test::thread_pools()) {
        INFO("isa " << isa_name(isa) << ", threads " << pool->size());
        const std::vector<float> got = runner->second(c, *pool, kernels_for(isa));
        REQUIRE(static_cast<int64_t>(got.size()) == expected.numel());
        CHECK(max_scaled_error(expected, got) <= 2e-5f);
      }
  }
  // Every op has fixtures: a generator that lost a kind of case fails here.
  for (const auto& [op, runner] : runners()) {
    INFO("op " << op);
    CHECK(per_op[op] > 0);
  }
}

TEST_CASE("numpy fixtures: a missing file names itself") {
  FixtureCase c{"no_such_case", "add", {}};
  CHECK_THROWS_WITH(c.array("input"), Catch::Contains("no_such_case.input.npy"));
}
