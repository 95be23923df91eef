// `ampi eval depth --ordinal`: depth order on real photos, judged by point pairs that a
// person labelled by looking at the photos (training/ordinal/, its INSTRUCTIONS.md).
//
// WHDR, the weighted human disagreement rate of Bell et al. 2014 (here every pair weighs
// the same): the share of labelled pairs whose order the disparity map gets wrong. A pair
// is read at its two points (bilinear, the map brought to the photo's size first); the map
// says "A nearer" when disparity(A) > disparity(B). Pairs labelled too close to call are
// left out. A tie counts as half an error, a coin toss: a constant map scores 0.5.
#pragma once
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace ampi {

struct OrdinalPair {
  cv::Point2f a, b;    // pixels of the upright photo (x right, y down)
  int a_nearer = 0;    // +1: A nearer, -1: B nearer, 0: too close to call
};

struct OrdinalPhoto {
  std::string photo;   // path relative to the photo folder, e.g. "sun80/x.jpg"
  cv::Size size;       // the photo's size when it was labelled
  std::string split;   // "train", "val", "test" (a validation photo's held-out pairs) or
                       // "holdout" (photos kept from training and from picking)
  std::vector<OrdinalPair> pairs;
};

// Reads an ordinal set (training/ordinal/ordinal.json.gz; OpenCV's FileStorage reads a name
// ending in .gz as gzip). Throws std::runtime_error
// "PATH: problem" for an unreadable or malformed file (missing field, label other than
// A, B or =, point outside its photo).
std::vector<OrdinalPhoto> read_ordinal_set(const std::string& path);

// Errors of one disparity map on one photo's ordered pairs.
struct OrdinalScore {
  double wrong = 0;  // ties count 0.5
  int pairs = 0;     // pairs labelled A or B
  void add(const OrdinalScore& other) { wrong += other.wrong, pairs += other.pairs; }
  double whdr() const { return pairs ? wrong / pairs : 0.0; }
};

// disparity: CV_32FC1 (larger = nearer) of any size; it is sampled at the pairs' points
// scaled from photo.size to its own. Throws std::invalid_argument for another type.
OrdinalScore score_ordinal(const cv::Mat& disparity, const OrdinalPhoto& photo);

}  // namespace ampi
