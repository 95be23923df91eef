// The convolution cases of the kernel tests, on the sweep harness (kernel_sweeps.h):
// one random layer per seed, and the comparison of Conv2d (any table, any pool) with the
// naive direct reference.
#pragma once
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "kernel_sweeps.h"
#include "kernels/conv.h"
#include "kernels/reference/conv_reference.h"

namespace ampi::test {

struct ConvCase {
  ConvParams p;
  int in_h = 1, in_w = 1;
  bool residual = false;
  uint32_t seed = 1;
};

inline std::string describe(const ConvCase& c) {
  const ConvParams& p = c.p;
  std::ostringstream s;
  s << "in " << c.in_h << "x" << c.in_w << "x" << p.in_c << ", out_c " << p.out_c << ", kernel "
    << p.kernel_h << "x" << p.kernel_w << ", stride " << p.stride_h << "x" << p.stride_w
    << ", pad t" << p.pad_top << " l" << p.pad_left << " b" << p.pad_bottom << " r" << p.pad_right
    << ", dilation " << p.dilation_h << "x" << p.dilation_w << ", groups " << p.groups << ", "
    << activation_name(p.act.kind) << (c.residual ? ", residual" : "") << ", seed " << c.seed;
  return s.str();
}

// The random tensors of one case, all from its seed.
struct ConvData {
  std::vector<float> in, weights, bias, residual;
  explicit ConvData(const ConvCase& c) {
    const ConvParams& p = c.p;
    const size_t out_size = static_cast<size_t>(p.out_h(c.in_h)) * p.out_w(c.in_w) * p.out_c;
    in = random_floats(static_cast<size_t>(c.in_h) * c.in_w * p.in_c, c.seed);
    weights = random_floats(static_cast<size_t>(p.out_c) * p.kernel_h * p.kernel_w * (p.in_c / p.groups),
                            c.seed + 1);
    bias = random_floats(p.out_c, c.seed + 2);
    if (c.residual) residual = random_floats(out_size, c.seed + 3, -4.0f, 4.0f);
  }
  const float* residual_or_null() const { return residual.empty() ? nullptr : residual.data(); }
};

// Expected output and the error scale of a case (kRelativeTolerance): the reference
// convolution before the epilogue, then the epilogue.
struct Expected {
  std::vector<float> out;
  float scale = 0.0f;
};

inline Expected expected_output(const ConvCase& c, const ConvData& d) {
  ConvParams linear = c.p;
  linear.act = {};
  Expected e;
  e.out.resize(static_cast<size_t>(c.p.out_h(c.in_h)) * c.p.out_w(c.in_w) * c.p.out_c);
  reference::conv2d_direct(linear, d.in.data(), c.in_h, c.in_w, d.weights.data(), d.bias.data(),
                           nullptr, e.out.data());
  e.scale = std::max(1e-3f, max_abs(e.out) + max_abs(d.residual));
  for (size_t i = 0; i < e.out.size(); ++i)
    e.out[i] = ampi::activate(e.out[i], c.p.act) + (d.residual.empty() ? 0.0f : d.residual[i]);
  return e;
}

// The path Conv2d takes for a case's layer.
inline Conv2d::Path path_of(const ConvCase& c) {
  const ConvData d(c);
  return Conv2d(c.p, d.weights.data(), nullptr).path();
}

// Runs Conv2d into a GuardedOutput: a value never written or one written past the end fails.
inline std::vector<float> run_conv(const ConvCase& c, const ConvData& d, const KernelTable& k,
                                   ThreadPool& pool) {
  const Conv2d conv(c.p, d.weights.data(), d.bias.data(), k);
  GuardedOutput out(static_cast<size_t>(c.p.out_h(c.in_h)) * c.p.out_w(c.in_w) * c.p.out_c);
  conv.run(d.in.data(), c.in_h, c.in_w, out.data(), d.residual_or_null(), pool);
  CHECK(out.guard_intact());
  return out.values();
}

// Conv2d on every runnable table (the pool's thread count) against the reference.
inline void check_all_isas(const ConvCase& c, ThreadPool& pool) {
  const ConvData d(c);
  const Expected e = expected_output(c, d);
  for (Isa isa : runnable_isas()) {
    INFO(describe(c) << ", isa " << isa_name(isa) << ", threads " << pool.size());
    const std::vector<float> got = run_conv(c, d, kernels_for(isa), pool);
    const float err = max_abs_diff(e.out.data(), got.data(), got.size());
    INFO("max error " << err << ", scale " << e.scale);
    REQUIRE(err <= kRelativeTolerance * e.scale);
  }
}

// On every runnable table: run(case, data, table, stream) with streaming stores equals it
// with plain stores bit for bit, and matches the reference.
template <class Run>
void check_streaming_all_isas(const ConvCase& c, Run run) {
  const ConvData d(c);
  const Expected e = expected_output(c, d);
  for (Isa isa : runnable_isas()) {
    INFO(describe(c) << ", isa " << isa_name(isa));
    const std::vector<float> streamed = run(c, d, kernels_for(isa), true);
    REQUIRE(streamed == run(c, d, kernels_for(isa), false));
    const float err = max_abs_diff(e.out.data(), streamed.data(), streamed.size());
    INFO("max error " << err << ", scale " << e.scale);
    REQUIRE(err <= kRelativeTolerance * e.scale);
  }
}

}  // namespace ampi::test
