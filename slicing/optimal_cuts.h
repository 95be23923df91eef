// Where to cut a disparity histogram into a given number of planes: exact dynamic
// programming over the 256 normalised levels (beyond the paper, which cuts where its
// transition index is largest; see slicing/adaptive.h, Slicer::Optimal).
//
// A plane is drawn at the mean disparity of its pixels, so every pixel is displaced by
// its distance to that mean when the camera moves; against a dense MPI the image error
// grows with that displacement. The cuts minimise the planes' summed squared disparity
// error (optimal 1-D quantisation: Jenks natural breaks, the Lloyd-Max objective solved
// exactly), so equal intervals with the same count are one of the candidates and can
// never do better on it.
#pragma once
#include <vector>

namespace ampi {

// Per-level pixel counts, summed once so that the squared error of any interval of levels
// costs O(1).
class LevelMoments {
 public:
  explicit LevelMoments(const std::vector<long long>& counts);
  long long pixels(int lo, int end) const;  // pixels at levels [lo, end)
  // Sum over the pixels at levels [lo, end) of (level - their mean level)^2.
  double squared_error(int lo, int end) const;
  int levels() const { return static_cast<int>(n_.size()) - 1; }

 private:
  std::vector<double> n_, s1_, s2_;  // prefix sums of count, count * level, count * level^2
};

// Boundaries {0, c_1, ..., c_{k-1}, L - 1} of the k planes (L = counts.size() levels,
// plane j holding [c_j, c_{j+1}), the last one holding level L - 1 too) minimising the
// summed squared_error of the planes plus cut_cost[c] for every cut c (cut_cost empty:
// none; else one entry per level, none negative). k is `planes`, or the most non-empty planes the
// levels allow when fewer (cuts lie in 1..L-2, so the top two levels are never parted);
// every plane holds a pixel. Among equal solutions the lowest cuts win. counts must hold
// at least 2 levels and a pixel; planes must be at least 1.
std::vector<int> optimal_boundaries(const std::vector<long long>& counts, int planes,
                                    const std::vector<double>& cut_cost = {});

}  // namespace ampi
