// The paper's pseudo ground truth for distillation: a teacher's 10x ensemble on one photo.
//
// The teacher runs at several resolutions (squares, or long sides with the aspect kept)
// on the photo and on its mirror image (the mirrored prediction flipped back). Each
// prediction is normalised on its own by its median and mean absolute deviation,
// d' = (d - median) / MAD (MiDaS' scale-and-shift
// alignment: a teacher's disparity scale drifts with the input size, and one extreme
// pixel cannot throw it off as it would min-max), resized bilinearly to the largest
// size, and the per-pixel median of all of them is the label; it is finally resized to
// the photo's own size and mapped to [0, 1]. training/distill.py is the same in numpy
// and the test holds the two together.
#pragma once
#include <functional>
#include <vector>

#include <opencv2/core.hpp>

namespace ampi {

// A teacher: the disparity (CV_32FC1, larger = nearer, any size) of an RGB image
// (CV_32FC3 in [0, 1]).
using Teacher = std::function<cv::Mat(const cv::Mat& rgb)>;

// (d - median(d)) / mean|d - median(d)| of a CV_32FC1 map; the median of an even count
// is the mean of the middle two (numpy's). A constant map stays all zeros.
cv::Mat normalise_median_mad(const cv::Mat& disparity);

// What each resolution sizes the photo to: the paper's square of that side, or the photo
// brought to that long side with its aspect kept (networks trained on whole photos of
// one aspect, as the bundled ones are, do worse on squeezed squares).
enum class EnsembleShape { kSquare, kAspectKept };

std::vector<cv::Size> ensemble_sizes(cv::Size photo, const std::vector<int>& resolutions, EnsembleShape shape);

// The per-pixel median of the 2 x resolutions.size() normalised predictions, at the
// largest of the sizes. rgb: CV_32FC3 in [0, 1].
cv::Mat ensemble_median(const cv::Mat& rgb, const Teacher& teacher, const std::vector<int>& resolutions,
                        EnsembleShape shape = EnsembleShape::kSquare);

// ensemble_median resized to the photo's size and mapped to [0, 1] (CV_32FC1).
cv::Mat pseudo_ground_truth(const cv::Mat& rgb, const Teacher& teacher, const std::vector<int>& resolutions,
                            EnsembleShape shape = EnsembleShape::kSquare);

}  // namespace ampi
