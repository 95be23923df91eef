// Slicing a disparity map into fronto-parallel planes: the paper's adaptive algorithm
// (Luvizon et al., WACV 2021, "adaptive slicing") and the uniform baseline.
//
// Both work on disparity normalised to the integers 0..255 (255 = nearest). A plane holds
// the pixels whose normalised disparity lies in [disparity_lo, disparity_hi); a plane
// whose disparity_hi is 255 also holds 255. Planes come back to front: farthest first.
// A plane's disparity is the mean of its pixels' normalised values (before rounding),
// taken in disparity because the renderer's homographies are linear in 1/z; its depth
// follows from the DepthRange through depth_from_disparity.
#pragma once
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mpi/mpi.h"

namespace ampi {

constexpr int kDisparityLevels = 256;

// How slice_adaptive places its cuts. Both run the paper's pipeline up to the greedy
// selection of transitions.
enum class Slicer {
  // The paper's algorithm: the selected transitions are the cuts.
  Paper,
  // The paper's selection decides how many planes the photo gets (the cuts it would make);
  // the cuts themselves then minimise the planes' squared disparity error over all pixels
  // (slicing/optimal_cuts.h). Beyond the paper: its transition index is largest where the
  // histogram is sparse, so it cuts off slivers at the ends and leaves one plane spanning
  // most of the disparity range (bench/RESULTS-slicing.md), while every pixel of a plane
  // moves with the plane's mean disparity.
  Optimal,
};

// "paper" or "optimal" (the --slicer values); throws std::runtime_error otherwise.
Slicer parse_slicer(const std::string& name);

// Every constant of the adaptive algorithm. eps, xi and threshold are the paper's
// values; the paper gives no filter sizes, so these defaults are ours. On the 0..255
// map the 3x3 Sobel response is 4 s across a step of s levels and 8 r along a slope of
// r levels per pixel: an edge starts at a step of about 13 levels (canny_high) and
// continues down to 5 (canny_low), while slopes under 2.5 levels per pixel never count.
struct SlicingParams {
  Slicer slicer = Slicer::Optimal;
  int max_planes = 8;         // at most this many planes, 1..255 (the paper's maximum count)
  double eps = 0.001;         // floor of h in the transition index's denominator
  int xi = 8;                 // a chosen transition suppresses t in [i - xi, i + xi]
  double threshold = 0.1;     // transitions need t above this
  // Beyond the paper: every plane must hold more than this fraction of an equal share
  // (1 / max_planes) of the histogram's mass, so no plane is a sliver of the sparse ends
  // (select_transitions' min_mass). 0 gives the paper's algorithm, which only refuses
  // to cut off an empty interval. With Slicer::Optimal it only changes the plane count.
  // (0.5 made the paper's cuts lose less to uniform ones; the optimal cuts need no guard.)
  double min_plane_share = 0.0;
  // Slicer::Optimal: a cut at level c also costs tear_penalty * (pixels of h at levels
  // c - 1 and c) / 2, in squared levels per pixel. A cut through a continuous surface opens
  // a crack along it as the camera moves, about as long as the surface has pixels at
  // the cut; h leaves depth edges out, where a cut opens nothing that is not already open.
  // 0: on the tuning photos 100 and 1000 lowered PSNR at 8 and 16 planes
  // (bench/RESULTS-slicing.md).
  double tear_penalty = 0.0;
  int bilateral_diameter = 5;           // pixel neighbourhood of the bilateral filter
  double bilateral_sigma_color = 20.0;  // in disparity levels
  double bilateral_sigma_space = 3.0;   // in pixels
  double canny_low = 20.0;              // hysteresis thresholds on the Sobel gradient
  double canny_high = 50.0;             // (L1 norm, 3x3 aperture)
  int border_erosion_size = 7;  // side of the square element that widens the edge band
  DepthRange range;             // maps plane disparities to depths
};

// disparity: CV_32FC1, larger = nearer, any range, finite values (throws
// std::invalid_argument otherwise). Min-max normalised and rounded to CV_8UC1 0..255;
// a constant map becomes all zeros.
cv::Mat normalize_disparity(const cv::Mat& disparity);
// The same normalisation without rounding: CV_32FC1 in [0, 255].
cv::Mat normalize_disparity_float(const cv::Mat& disparity);

// The paper's algorithm, its cuts placed as p.slicer says. Throws std::invalid_argument
// for a bad map or bad params.
std::vector<Plane> slice_adaptive(const cv::Mat& disparity, const SlicingParams& p = {});

// `planes` equal intervals of normalised disparity (1..255 of them). A plane that holds
// no pixel is dropped rather than kept: an empty layer would cost rendering time and
// show nothing. So fewer planes may come back; the others keep their equal intervals.
std::vector<Plane> slice_uniform(const cv::Mat& disparity, int planes, const DepthRange& range = {});

// ---- the steps of slice_adaptive, pure functions exposed for tests ----------------------

// The edge-aware histogram of the paper: bilateral filter, Canny edges, the edge band
// widened by border_erosion_size and left out; normalised to sum 1. When the band covers
// every pixel (tiny maps) the filtered map's full histogram is used instead.
std::vector<double> slicing_histogram(const cv::Mat& normalized, const SlicingParams& p);

// Second difference h[i-1] - 2 h[i] + h[i+1]; 0 at the two end bins, which are always
// boundaries and never candidates.
std::vector<double> histogram_laplacian(const std::vector<double>& h);

// t = laplacian(h) / max(eps, h).
std::vector<double> transition_index(const std::vector<double>& h, double eps);

// Greedy selection: repeatedly take the largest t_i (the lowest i among equals), store
// i and zero t in [i - xi, i + xi], until no t_i exceeds threshold or max_selected are
// stored. The end bins are not candidates (they are always boundaries). One guard beyond
// the paper: a candidate that would leave an interval on either side of it holding no
// more than min_mass of h is dropped (only its own t is zeroed). With min_mass 0 that
// refuses only empty planes. Larger values matter because t = laplacian(h) / h is
// largest where h is smallest: on a smooth depth map the paper's rule cuts first at the
// sparse ends, leaving slivers of a few hundred pixels while one plane spans most of
// the disparity range (bench/RESULTS-slicing.md). The count limit counts planes that
// pass the guard. Returns the indices in the order chosen.
std::vector<int> select_transitions(const std::vector<double>& t, const std::vector<double>& h,
                                    int xi, double threshold, int max_selected, double min_mass = 0.0);

// Sorted boundaries {0, selected..., 255}, then every interval holding no pixel of
// `bin_counts` merged into its lower neighbour (the upper one for the first interval).
std::vector<int> plane_boundaries(const std::vector<int>& selected,
                                  const std::vector<long long>& bin_counts);

// One past the last level an interval [lo, hi) holds: the top level 255 belongs to the
// interval that ends there.
inline int interval_end(int hi) { return hi == kDisparityLevels - 1 ? kDisparityLevels : hi; }

// Index of the plane holding normalised disparity `level` (0..255), or -1 if none does
// (uniform slicing drops empty planes, leaving gaps).
int plane_of_level(const std::vector<Plane>& planes, int level);

}  // namespace ampi
