// `ampi distill`'s folder of labels: one 16-bit disparity PNG per photo, made by a
// teacher's ensemble (distill/ensemble.h), resumable across runs.
//
// LABELS/labels.tsv records how the labels were made and which photo each is of:
//
//   ampi-distill	1
//   teacher	FILE NAME	ARCH	VARIANT
//   resolutions	518,434,...	(a third field "aspect kept" for EnsembleShape::kAspectKept)
//   images	/absolute/path/of/the/photo/folder
//   LABEL.png	PHOTO PATH RELATIVE TO images
//   ...
//
// A photo's line is appended once its PNG is in place (written to a temporary name and
// renamed), so a run that stops at any moment resumes where it stopped: photos with a
// line are skipped. A folder made with another teacher, other resolutions or another
// photo folder is refused, as is a non-empty folder without labels.tsv (nothing the user
// had is overwritten). training/train_depth.py reads the folder as `--data distilled:LABELS`.
#pragma once
#include <string>
#include <vector>

#include "distill/ensemble.h"

namespace ampi {

// What the folder's labels are made with; the header of labels.tsv.
struct LabelRecipe {
  std::string teacher_file;  // the weight file's name (no folder)
  std::string architecture, variant;
  std::vector<int> resolutions;
  EnsembleShape shape = EnsembleShape::kSquare;
  std::string images;  // the photo folder, absolute
};

// "a_b_c.png" for the photo a/b/c.jpg under the photo folder.
std::string label_name(const std::string& relative_photo);

class LabelFolder {
 public:
  // Creates `folder` or opens an existing one made with the same recipe. Throws
  // std::runtime_error "FOLDER: problem" otherwise.
  LabelFolder(const std::string& folder, const LabelRecipe& recipe);

  bool has(const std::string& relative_photo) const;
  // Writes the label of one photo (disparity CV_32FC1) and records it.
  void add(const std::string& relative_photo, const cv::Mat& disparity);
  size_t size() const { return done_.size(); }

 private:
  std::string folder_, manifest_;
  std::vector<std::string> done_;  // relative photo paths with a label, sorted
};

}  // namespace ampi
