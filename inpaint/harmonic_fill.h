// Membrane (harmonic) hole filling: every unknown pixel ends as the mean of its four
// neighbours while known pixels keep their colour, i.e. the solution of Laplace's
// equation with the known colours as boundary values (Neumann at the image's edges).
// It is the smoothest fill that meets the known colours at the hole's edge, so a hole's
// margin continues its own side of the boundary, where push-pull blends in the averages
// of coarse pyramid cells. On the held-out photos of `ampi eval inpaint` that is worth
// about 0.3 dB over push-pull (training/INPAINT.md).
//
// Solved by successive over-relaxation, as a cascade: the known colours are averaged
// down to at most coarsest_side pixels, push-pull's estimate (made at most start_side
// pixels large and averaged down) starts the unknown ones there, and all of them are
// relaxed; each finer level starts its unknown pixels from the
// coarser solution and relaxes a few sweeps more, only within `band` pixels of the known
// ones (where the margins to fill lie; far inside a hole the coarse solution is already
// as smooth as the answer). So the work grows with the margins, not with the holes or
// the sweeps a wide hole would need (timings: training/INPAINT.md, "Speed"). A sweep is
// red-black: pixels with (x + y) even from their odd neighbours, then the odd ones from
// the even, so each half-sweep is order-free (channels run in parallel, results do not
// depend on the thread count). training/inpaint_push_pull.py does the same steps in
// numpy.
#pragma once
#include <opencv2/core.hpp>

#include "engine/thread_pool.h"

namespace ampi {

// Chosen on 10 held-out photos (`ampi eval inpaint --limit 10`, rebuilt with each
// setting; at most 1024 px; push-pull 16.22 dB). One level (no cascade) with 25, 50, 100, 200 and 400 sweeps: 16.48, 16.54,
// 16.58, 16.61 and 16.62 dB. These defaults: 16.57 dB in 41 % of the time of one level
// with 100 sweeps (3.5 s against 8.4 s for the 70 fills); coarsest side 128 instead:
// 16.52; push-pull made on the coarsest level itself instead of at most 1024 px: 16.50.
struct HarmonicFill {
  int coarsest_side = 256;    // levels halve until the long side is at most this
  int start_side = 1024;      // push-pull runs on the first level at most this large
  int coarsest_sweeps = 100;  // sweeps on the coarsest level, over all of it
  int sweeps = 25;            // sweeps on every finer level, within `band`
  int band = 48;              // pixels (3x3 dilations) from the known ones; 0: all
  float omega = 1.95f;        // over-relaxation, in (0, 2)
};

// The float estimate: CV_32FC3 at every pixel (the known colour where known), from an
// 8-bit BGR(A) image. Empty when no pixel is known. Throws std::invalid_argument for
// bad inputs or parameters.
cv::Mat harmonic_estimate(const cv::Mat& image, const cv::Mat& known, const HarmonicFill& params = {},
                          ThreadPool& pool = default_pool());

// image: CV_8UC3 or CV_8UC4; known, fill: CV_8UC1 of its size. A copy of image whose
// colour channels take the 8-bit harmonic estimate where fill != 0.
cv::Mat harmonic_fill(const cv::Mat& image, const cv::Mat& known, const cv::Mat& fill,
                      const HarmonicFill& params = {}, ThreadPool& pool = default_pool());

}  // namespace ampi
