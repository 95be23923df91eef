// The optimal cut placement (slicing/optimal_cuts.h) against brute force over every cut
// set, against equal intervals, and inside slice_adaptive.
#include <catch2/catch.hpp>
#include <limits>
#include <random>
#include <vector>

#include "slicing/adaptive.h"
#include "slicing/optimal_cuts.h"

using namespace ampi;

namespace {

// Summed squared error of the planes between sorted boundaries {0, ..., L - 1} (the last
// plane holding level L - 1) plus the costs of the cuts, or infinity if a plane holds no
// pixel.
double planes_error(const LevelMoments& m, const std::vector<int>& boundaries,
                    const std::vector<double>& cut_cost = {}) {
  double sum = 0;
  for (size_t j = 1; j + 1 < boundaries.size() && !cut_cost.empty(); ++j) sum += cut_cost[boundaries[j]];
  for (size_t j = 0; j + 1 < boundaries.size(); ++j) {
    const int lo = boundaries[j];
    const int end = j + 2 == boundaries.size() ? m.levels() : boundaries[j + 1];
    if (m.pixels(lo, end) <= 0) return std::numeric_limits<double>::infinity();
    sum += m.squared_error(lo, end);
  }
  return sum;
}

// The least error of exactly `planes` non-empty planes, trying every set of cuts in 1..L-2.
double brute_force_error(const LevelMoments& m, int planes, const std::vector<double>& cut_cost = {}) {
  const int levels = m.levels();
  double least = std::numeric_limits<double>::infinity();
  for (unsigned mask = 0; mask < (1u << (levels - 2)); ++mask) {
    if (__builtin_popcount(mask) != planes - 1) continue;
    std::vector<int> b = {0};
    for (int c = 1; c <= levels - 2; ++c)
      if (mask >> (c - 1) & 1u) b.push_back(c);
    b.push_back(levels - 1);
    least = std::min(least, planes_error(m, b, cut_cost));
  }
  return least;
}

std::vector<long long> random_counts(std::mt19937& rng, int levels, double occupied) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<long long> counts(levels, 0);
  for (long long& c : counts)
    if (u(rng) < occupied) c = 1 + static_cast<long long>(1000 * u(rng) * u(rng));
  counts[static_cast<size_t>(u(rng) * levels) % levels] += 1;  // at least one pixel
  return counts;
}

}  // namespace

TEST_CASE("LevelMoments: pixels and squared error of an interval") {
  const LevelMoments m({2, 0, 1, 1});  // levels 0, 0, 2, 3
  CHECK(m.levels() == 4);
  CHECK(m.pixels(0, 4) == 4);
  CHECK(m.pixels(1, 2) == 0);
  CHECK(m.squared_error(1, 2) == 0);
  CHECK(m.squared_error(2, 4) == Approx(0.5));        // 2, 3 around 2.5
  CHECK(m.squared_error(0, 4) == Approx(2 * 1.5625 + 0.5625 + 3.0625));  // around 1.25
}

TEST_CASE("optimal_boundaries finds the least error of every cut set (brute force)") {
  for (uint32_t seed = 1; seed <= 60; ++seed) {
    std::mt19937 rng(seed);
    const int levels = 3 + static_cast<int>(seed % 10);  // 3..12 levels
    const std::vector<long long> counts = random_counts(rng, levels, 0.2 + 0.1 * (seed % 7));
    const LevelMoments m(counts);
    std::vector<double> cut_cost;  // none for even seeds, random costs for odd ones
    std::uniform_real_distribution<double> u(0.0, 2000.0);
    for (int c = 0; c < levels && seed % 2; ++c) cut_cost.push_back(u(rng));
    for (int planes = 1; planes <= 6; ++planes) {
      INFO("seed " << seed << ", " << levels << " levels, " << planes << " planes");
      const std::vector<int> b = optimal_boundaries(counts, planes, cut_cost);
      REQUIRE(b.front() == 0);
      REQUIRE(b.back() == levels - 1);
      for (size_t j = 1; j < b.size(); ++j) CHECK(b[j] > b[j - 1]);
      const int made = static_cast<int>(b.size()) - 1;
      CHECK(made <= planes);
      if (made < planes) CHECK(brute_force_error(m, made + 1) == std::numeric_limits<double>::infinity());
      CHECK(planes_error(m, b, cut_cost) == Approx(brute_force_error(m, made, cut_cost)).margin(1e-9));
    }
  }
}

TEST_CASE("optimal_boundaries: lowest cuts among equals, the top two levels never parted") {
  // Two equal spikes with an empty gap: any cut in the gap is as good; the lowest wins.
  CHECK(optimal_boundaries({5, 0, 0, 0, 5, 0}, 2) == std::vector<int>{0, 1, 5});
  // Pixels only at the top two levels: one plane, whatever is asked.
  CHECK(optimal_boundaries({0, 0, 0, 3, 4}, 3) == std::vector<int>{0, 4});
}

TEST_CASE("optimal_boundaries refuses bad input") {
  CHECK_THROWS_AS(optimal_boundaries({1, 1}, 0), std::invalid_argument);
  CHECK_THROWS_AS(optimal_boundaries({7}, 1), std::invalid_argument);
  CHECK_THROWS_AS(optimal_boundaries({1, 1, 1}, 2, {0.0, 1.0}), std::invalid_argument);
  CHECK_THROWS_AS(optimal_boundaries({0, 0, 0}, 2), std::invalid_argument);
}

TEST_CASE("optimal cuts never have more error than equal intervals with the same count") {
  for (uint32_t seed = 1; seed <= 30; ++seed) {
    std::mt19937 rng(seed);
    const std::vector<long long> counts = random_counts(rng, kDisparityLevels, 0.1 + 0.03 * (seed % 30));
    const LevelMoments m(counts);
    for (int planes : {2, 4, 8, 16}) {
      // slice_uniform's intervals, empty ones dropped by joining them to a neighbour
      // (which leaves the error unchanged).
      std::vector<int> uniform = {0};
      for (int j = 1; j < planes; ++j) uniform.push_back(kDisparityLevels * j / planes);
      uniform.push_back(kDisparityLevels - 1);
      std::vector<int> kept = {0};
      for (size_t j = 1; j + 1 < uniform.size(); ++j)
        if (m.pixels(kept.back(), uniform[j]) > 0 && m.pixels(uniform[j], kDisparityLevels) > 0)
          kept.push_back(uniform[j]);
      kept.push_back(kDisparityLevels - 1);
      const std::vector<int> best = optimal_boundaries(counts, static_cast<int>(kept.size()) - 1);
      INFO("seed " << seed << ", " << planes << " planes");
      CHECK(best.size() == kept.size());
      CHECK(planes_error(m, best) <= planes_error(m, kept) * (1 + 1e-12));
    }
  }
}
