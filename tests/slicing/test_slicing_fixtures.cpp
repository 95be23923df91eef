// The transition index, the greedy selection and the optimal cuts against the independent
// numpy reference in tests/fixtures/slicing/make_slicing_fixtures.py (same histograms in,
// t, the chosen indices and the optimal boundaries out).
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "slicing/adaptive.h"
#include "slicing/optimal_cuts.h"
#include "weights_format/npy.h"

using namespace ampi;

namespace {

Tensor fixture(const char* name) {
  return read_npy(std::string(AMPI_SOURCE_DIR) + "/tests/fixtures/slicing/" + name);
}

std::vector<double> row(const Tensor& t, int64_t r) {
  const int64_t n = t.dim(1);
  return std::vector<double>(t.f32() + r * n, t.f32() + (r + 1) * n);
}

}  // namespace

TEST_CASE("transition index and selection match the numpy reference") {
  const Tensor hist = fixture("hist.npy"), params = fixture("params.npy"), ts = fixture("t.npy"),
               selected = fixture("selected.npy");
  REQUIRE(hist.rank() == 2);
  REQUIRE(hist.dim(1) == kDisparityLevels);
  const int64_t cases = hist.dim(0);
  REQUIRE(cases >= 10);
  REQUIRE(params.dim(0) == cases);
  REQUIRE(ts.dim(0) == cases);
  REQUIRE(selected.dim(0) == cases);
  for (int64_t c = 0; c < cases; ++c) {
    const std::vector<double> h = row(hist, c), p = row(params, c), expected_t = row(ts, c);
    const double eps = p[0], threshold = p[2];
    const int xi = static_cast<int>(p[1]), max_selected = static_cast<int>(p[3]);
    INFO("fixture case " << c << ": eps " << eps << ", xi " << xi << ", threshold " << threshold << ", max "
                         << max_selected);
    const std::vector<double> t = transition_index(h, eps);
    for (int i = 0; i < kDisparityLevels; ++i) {
      INFO("bin " << i);
      // The reference t is stored in f64 and read back as f32.
      CHECK(t[i] == Approx(expected_t[i]).epsilon(1e-6).margin(1e-30));
    }
    std::vector<int> expected;
    for (double v : row(selected, c))
      if (v >= 0) expected.push_back(static_cast<int>(v));
    CHECK(select_transitions(t, h, xi, threshold, max_selected) == expected);
  }
}

TEST_CASE("optimal cuts match the numpy reference for the count the selection makes") {
  const Tensor counts = fixture("counts.npy"), selected = fixture("selected.npy"), optimal = fixture("optimal.npy");
  REQUIRE(counts.rank() == 2);
  REQUIRE(counts.dim(1) == kDisparityLevels);
  REQUIRE(counts.dim(0) >= 10);
  REQUIRE(selected.dim(0) == counts.dim(0));
  REQUIRE(optimal.dim(0) == counts.dim(0));
  for (int64_t c = 0; c < counts.dim(0); ++c) {
    std::vector<long long> pixels;
    for (double v : row(counts, c)) pixels.push_back(static_cast<long long>(v));  // exact: below 2^24
    int planes = 1;
    for (double v : row(selected, c)) planes += v >= 0;
    std::vector<int> expected;
    for (double v : row(optimal, c))
      if (v >= 0) expected.push_back(static_cast<int>(v));
    INFO("fixture case " << c << ", " << planes << " planes");
    CHECK(optimal_boundaries(pixels, planes) == expected);
  }
}
