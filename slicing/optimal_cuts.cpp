#include "slicing/optimal_cuts.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace ampi {

LevelMoments::LevelMoments(const std::vector<long long>& counts)
    : n_(counts.size() + 1, 0.0), s1_(counts.size() + 1, 0.0), s2_(counts.size() + 1, 0.0) {
  for (size_t l = 0; l < counts.size(); ++l) {
    const double c = static_cast<double>(counts[l]), v = static_cast<double>(l);
    n_[l + 1] = n_[l] + c;
    s1_[l + 1] = s1_[l] + c * v;
    s2_[l + 1] = s2_[l] + c * v * v;
  }
}

long long LevelMoments::pixels(int lo, int end) const { return static_cast<long long>(n_[end] - n_[lo]); }

double LevelMoments::squared_error(int lo, int end) const {
  const double n = n_[end] - n_[lo];
  if (n <= 0) return 0.0;
  const double s1 = s1_[end] - s1_[lo];
  // Sum of squares minus n mean^2; never negative, rounding aside.
  return std::max(0.0, (s2_[end] - s2_[lo]) - s1 * s1 / n);
}

namespace {

// best[k][e]: the least cost of k non-empty planes covering the levels [0, e); from[k][e]:
// where the k-th of them starts. Plane ends ("end" = one past its last level) are cuts,
// 1..L-2, or L for the top plane (which so holds the top two levels).
struct CutTable {
  std::vector<std::vector<double>> best;
  std::vector<std::vector<int>> from;
};

CutTable fill_cut_table(const LevelMoments& m, int max_planes, const std::vector<double>& cut_cost) {
  const int levels = m.levels();
  const double inf = std::numeric_limits<double>::infinity();
  CutTable t{std::vector<std::vector<double>>(max_planes + 1, std::vector<double>(levels + 1, inf)),
             std::vector<std::vector<int>>(max_planes + 1, std::vector<int>(levels + 1, -1))};
  auto is_end = [&](int e) { return (e >= 1 && e <= levels - 2) || e == levels; };
  auto cost_of_cut = [&](int c) { return cut_cost.empty() ? 0.0 : cut_cost[c]; };
  for (int e = 1; e <= levels; ++e)
    if (is_end(e) && m.pixels(0, e) > 0) t.best[1][e] = m.squared_error(0, e), t.from[1][e] = 0;
  for (int k = 2; k <= max_planes; ++k)
    for (int e = 2; e <= levels; ++e) {
      if (!is_end(e)) continue;
      for (int s = 1; s < e && s <= levels - 2; ++s) {  // the k-th plane is [s, e)
        if (t.best[k - 1][s] == inf || m.pixels(s, e) <= 0) continue;
        const double cost = t.best[k - 1][s] + cost_of_cut(s) + m.squared_error(s, e);
        if (cost < t.best[k][e]) t.best[k][e] = cost, t.from[k][e] = s;  // strict: lowest s among equals
      }
    }
  return t;
}

// The boundaries of the most planes (at most max_planes) that cover every level.
std::vector<int> trace_boundaries(const CutTable& t, int max_planes, int levels) {
  int k = max_planes;
  while (t.best[k][levels] == std::numeric_limits<double>::infinity()) --k;  // k = 1 always covers
  std::vector<int> boundaries = {levels - 1};
  for (int e = levels; k > 1; --k) {
    e = t.from[k][e];
    boundaries.push_back(e);
  }
  boundaries.push_back(0);
  std::reverse(boundaries.begin(), boundaries.end());
  return boundaries;
}

}  // namespace

std::vector<int> optimal_boundaries(const std::vector<long long>& counts, int planes,
                                    const std::vector<double>& cut_cost) {
  const int levels = static_cast<int>(counts.size());
  if (levels < 2 || planes < 1) throw std::invalid_argument("optimal_boundaries: need 2 levels and 1 plane");
  if (!cut_cost.empty() && cut_cost.size() != counts.size())
    throw std::invalid_argument("optimal_boundaries: cut_cost needs one entry per level");
  const LevelMoments m(counts);
  if (m.pixels(0, levels) <= 0) throw std::invalid_argument("optimal_boundaries: the histogram holds no pixel");
  const int max_planes = std::min(planes, levels - 1);
  return trace_boundaries(fill_cut_table(m, max_planes, cut_cost), max_planes, levels);
}

}  // namespace ampi
