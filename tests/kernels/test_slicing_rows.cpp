// The slicer's row kernels (slicing/row_kernels.h): every runnable ISA against the scalar
// reference, over the harness's row lengths (kernel_sweeps.h). They need no OpenCV, so
// they live in the core and the aarch64 build runs this file under qemu for NEON. The
// whole filter, and the reference against OpenCV's, is tested in
// tests/slicing/test_bilateral.cpp.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "engine/isa.h"
#include "kernel_sweeps.h"
#include "slicing/row_kernels.h"

using namespace ampi;

TEST_CASE("every normalize_row variant equals the scalar reference bit for bit") {
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  // (lo, hi) ranges: ordinary, narrow at a large offset, and the whole float range.
  const std::pair<float, float> ranges[] = {{-2.0f, 7.0f}, {1000.0f, 1000.5f}, {-3e38f, 3e38f}};
  for (Isa isa : runnable_isas()) {
    const slicing::SlicingKernels kernels = slicing::slicing_kernels(isa);
    for (auto [lo, hi] : ranges)
      for (int n : test::length_sweep()) {
        std::vector<float> in(n);
        for (float& v : in) v = lo + unit(rng) * (hi - lo);
        in[0] = lo;
        in[n - 1] = hi;
        const double scale = 255.0 / (double(hi) - double(lo));
        std::vector<float> want_value(n), got_value(n);
        std::vector<uint8_t> want_level(n), got_level(n);
        slicing::scalar::normalize_row(in.data(), n, lo, scale, want_value.data(), want_level.data());
        kernels.normalize_row(in.data(), n, lo, scale, got_value.data(), got_level.data());
        INFO(isa_name(isa) << " range " << lo << ".." << hi << " n " << n);
        REQUIRE(got_value == want_value);
        REQUIRE(got_level == want_level);
        CHECK(want_level[n - 1] == 255);
        if (n > 1) CHECK(want_level[0] == 0);
      }
  }
}

TEST_CASE("every range_row variant finds the scalar range and every non-finite value") {
  std::mt19937 rng(31);
  std::uniform_real_distribution<float> value(-1e6f, 1e6f);
  const float bad[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                       -std::numeric_limits<float>::infinity()};
  for (Isa isa : runnable_isas()) {
    const slicing::RangeRowFn range_row = slicing::slicing_kernels(isa).range_row;
    for (int n : test::length_sweep()) {
      std::vector<float> in(n);
      for (float& v : in) v = value(rng);
      slicing::ValueRange want{in[0], in[0], true}, got = want;
      slicing::scalar::range_row(in.data(), n, want);
      range_row(in.data(), n, got);
      INFO(isa_name(isa) << " n " << n);
      REQUIRE(got.finite);
      CHECK(got.lo == *std::min_element(in.begin(), in.end()));
      CHECK(got.hi == *std::max_element(in.begin(), in.end()));
      CHECK(got.lo == want.lo);
      CHECK(got.hi == want.hi);
      for (int at = 0; at < n; ++at)  // every position: vector body and tail
        for (float b : bad) {
          std::vector<float> spoiled = in;
          spoiled[at] = b;
          slicing::ValueRange r{in[0], in[0], true};
          range_row(spoiled.data(), n, r);
          REQUIRE_FALSE(r.finite);
        }
    }
  }
}

namespace {

// A padded map of random levels and the pairs of a disk of radius r, as
// slicing/bilateral.cpp builds them.
struct PairSetup {
  int r, width, stride;
  std::vector<uint8_t> padded;  // rows [-r, r], columns [-2r, width + 2r)
  std::vector<int64_t> offset;
  std::vector<float> space, log2_space, color;
  slicing::BilateralPairs pairs;

  PairSetup(int radius, int w, double sigma_color, double sigma_space, uint32_t seed)
      : r(radius), width(w), stride(w + 4 * radius), padded(static_cast<size_t>(stride) * (2 * radius + 1)) {
    std::mt19937 rng(seed);
    for (uint8_t& v : padded) v = static_cast<uint8_t>(rng() % 256);
    const double space_coeff = -0.5 / (sigma_space * sigma_space), color_coeff = -0.5 / (sigma_color * sigma_color);
    for (int i = 0; i <= r; ++i)
      for (int j = (i == 0 ? 1 : -r); j <= r; ++j) {
        const double r2 = double(i) * i + double(j) * j;
        if (std::sqrt(r2) > r) continue;
        offset.push_back(int64_t{i} * stride + j);
        space.push_back(static_cast<float>(std::exp(r2 * space_coeff)));
        log2_space.push_back(static_cast<float>(r2 * space_coeff * M_LOG2E));
      }
    for (int d = 0; d < 256; ++d) color.push_back(static_cast<float>(std::exp(d * d * color_coeff)));
    pairs = {static_cast<int>(offset.size()), offset.data(), space.data(), log2_space.data(), color.data(),
             static_cast<float>(color_coeff * M_LOG2E)};
  }
  const uint8_t* row_start() const { return padded.data() + static_cast<size_t>(r) * stride + r; }  // column -r
};

}  // namespace

TEST_CASE("every bilateral weights variant matches the reference's tables") {
  for (Isa isa : runnable_isas()) {
    const slicing::SlicingKernels kernels = slicing::slicing_kernels(isa);
    for (int r : {1, 2, 4})
      for (int w : test::length_sweep()) {
        const PairSetup s(r, w, 20.0, 3.0, static_cast<uint32_t>(r * 100 + w));
        const int n = w + 2 * r;
        std::vector<std::vector<float>> want(s.pairs.count, std::vector<float>(n)), got = want;
        std::vector<float*> want_rows, got_rows;
        for (int h = 0; h < s.pairs.count; ++h) {
          want_rows.push_back(want[h].data());
          got_rows.push_back(got[h].data());
        }
        slicing::scalar::bilateral_weights(s.row_start(), n, s.pairs, want_rows.data());
        kernels.bilateral_weights(s.row_start(), n, s.pairs, got_rows.data());
        INFO(isa_name(isa) << " radius " << r << " width " << w);
        for (int h = 0; h < s.pairs.count; ++h)
          for (int x = 0; x < n; ++x) REQUIRE(got[h][x] == Approx(want[h][x]).epsilon(1e-5).margin(1e-30));
      }
  }
}

TEST_CASE("every bilateral combine variant matches the reference within one level") {
  for (Isa isa : runnable_isas()) {
    const slicing::SlicingKernels kernels = slicing::slicing_kernels(isa);
    long long pixels = 0, differing = 0;
    for (int r : {1, 2, 4})
      for (int w : test::length_sweep()) {
        const PairSetup s(r, w, 20.0, 3.0, static_cast<uint32_t>(r * 1000 + w));
        // The taps of the centre row: the centre (weight 1) and each pair's forward tap,
        // weighed with the reference's weights, so only the sums can differ.
        const int n = w + 2 * r;
        std::vector<std::vector<float>> weights(s.pairs.count, std::vector<float>(n));
        std::vector<float*> rows;
        for (auto& row : weights) rows.push_back(row.data());
        slicing::scalar::bilateral_weights(s.row_start(), n, s.pairs, rows.data());
        const std::vector<float> ones(w, 1.0f);
        std::vector<const float*> tap_weight{ones.data()};
        std::vector<int64_t> tap_offset{0};
        for (int h = 0; h < s.pairs.count; ++h) {
          tap_weight.push_back(weights[h].data() + r);
          tap_offset.push_back(s.offset[h]);
        }
        const slicing::BilateralTaps taps{static_cast<int>(tap_weight.size()), tap_offset.data(), tap_weight.data()};
        std::vector<uint8_t> want(w), got(w);
        slicing::scalar::bilateral_combine(s.row_start() + r, w, taps, want.data());
        kernels.bilateral_combine(s.row_start() + r, w, taps, got.data());
        INFO(isa_name(isa) << " radius " << r << " width " << w);
        for (int x = 0; x < w; ++x) {
          REQUIRE(std::abs(got[x] - want[x]) <= 1);
          differing += got[x] != want[x];
        }
        pixels += w;
      }
    // FMA against a product and a sum: a level apart only at a near tie.
    INFO(isa_name(isa) << ": " << differing << " of " << pixels << " differ");
    CHECK(differing * 100 <= pixels);
  }
}

TEST_CASE("every snap_row variant equals the scalar reference bit for bit") {
  std::mt19937 rng(41);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), colour(0.0f, 255.0f), coeff(-0.02f, 0.02f);
  for (Isa isa : runnable_isas()) {
    const slicing::SnapRowFn snap_row = slicing::slicing_kernels(isa).snap_row;
    for (int n : test::length_sweep())
      for (float margin : {0.0f, 0.1f}) {
        std::vector<float> lo(n), hi(n), d(n), blue(n), green(n), red(n), a0(n), a1(n), a2(n), b(n);
        for (int x = 0; x < n; ++x) {
          lo[x] = unit(rng);
          hi[x] = lo[x] + (x % 5 == 0 ? 0.05f : unit(rng));  // some spreads below min_step
          // Inside the ramp, at either extreme, and exactly at the middle.
          const int kind = x % 4;
          d[x] = kind == 0 ? lo[x] : kind == 1 ? hi[x] : kind == 2 ? 0.5f * (lo[x] + hi[x]) : lo[x] + unit(rng) * (hi[x] - lo[x]);
          blue[x] = colour(rng), green[x] = colour(rng), red[x] = colour(rng);
          a0[x] = coeff(rng), a1[x] = coeff(rng), a2[x] = coeff(rng), b[x] = unit(rng) - 0.5f;
        }
        const slicing::SnapRowInputs in{d.data(), blue.data(), green.data(), red.data(), a0.data(),
                                        a1.data(), a2.data(), b.data(), lo.data(), hi.data()};
        std::vector<float> want(n), got(n);
        std::vector<uint8_t> want_band(n), got_band(n);
        slicing::scalar::snap_row(in, n, 0.1f, margin, want.data(), want_band.data());
        snap_row(in, n, 0.1f, margin, got.data(), got_band.data());
        INFO(isa_name(isa) << " n " << n << " margin " << margin);
        REQUIRE(got == want);
        REQUIRE(got_band == want_band);
        for (int x = 0; x < n; ++x) {
          const bool edge = hi[x] - lo[x] >= 0.1f;
          CHECK(want_band[x] == (edge ? 255 : 0));
          // Snapped values are one of the extremes; the rest are untouched.
          CHECK((want[x] == d[x] || want[x] == lo[x] || want[x] == hi[x]));
          if (!edge) CHECK(want[x] == d[x]);
        }
      }
  }
}
