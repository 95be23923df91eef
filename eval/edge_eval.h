// `ampi eval edges`: do objects stay whole when the camera moves? Scenes of a few
// fronto-parallel textured surfaces (a background and objects in front of it) whose
// every new view is known exactly: each surface warped by its own homography, composited
// back to front. An MPI made from the scene's photo and a soft disparity map (made at a
// fraction of the size and enlarged bilinearly, as a network's is) is rendered at the
// same poses and compared with the exact views pixel by pixel.
//
// What a rendered pixel shows is traced, not guessed from its colour: the MPI's layers
// are redrawn with labels instead of colours (a layer's own pixels, which show the
// photo, get the share of each surface in that photo pixel; the pixels the inpainter
// invented get the push-pull fill of their layer's own labels, the way colour spreads
// into the margin) and rendered at the pose like the colours. A pixel is wrong
// where under half of it is the surface the exact view shows there, and an object is
// involved (the exact surface or the one shown most is an object); pixels within one
// pixel of a surface's border in the exact view (mixed colour there) are left out.
// Fringe: pixels of revealed surface (hidden in the photo by a nearer surface, visible
// in the view) that show mostly a nearer surface: foreground colour smeared into the
// uncovered background. Holes: pixels no layer covers (composited over black), mostly
// uncovered background beyond the filled margin.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "mpi/mpi.h"
#include "render/pose.h"

namespace ampi {

struct EdgeSurface {
  std::string name;
  cv::Mat bgr;       // CV_8UC3: the surface's texture over the whole frame
  cv::Mat coverage;  // CV_32FC1 in [0, 1]: how much of each pixel it covers (antialiased)
  double disparity = 0;
};

struct EdgeScene {
  std::string name;
  std::vector<EdgeSurface> surfaces;  // back to front; surfaces[0] is the background, covering all
  cv::Mat photo;                      // CV_8UC3: the surfaces composited
  cv::Mat disparity;                  // CV_32FC1: the exact map (each pixel its frontmost surface's)
};

// The scene set: a disk (the plainest case of a torn edge), a thin pole, a person-like silhouette and
// two objects at different depths, at `size`. Textures are smooth noise in separate hues
// (background green-grey, objects red and blue) from `seed`; with a `texture_photo`
// (CV_8UC3) they are crops of it instead.
std::vector<EdgeScene> edge_scenes(cv::Size size, uint32_t seed, const cv::Mat& texture_photo = {});

// The exact map made soft: reduced by `factor` (INTER_AREA) and enlarged back bilinearly;
// factor 1 leaves it hard.
cv::Mat soften_disparity(const cv::Mat& disparity, int factor);

// The exact MPI of a scene: one layer per surface (alpha = coverage) at the depth its
// disparity has after ampi's normalisation (the scene's range over 0..255, mapped by
// `range`), with `camera`.
Mpi exact_mpi(const EdgeScene& scene, const Camera& camera, const DepthRange& range);

struct EdgeScore {
  double motion_px = 0;       // how far the nearest object moves against the background
  int64_t object_pixels = 0;  // pixels the exact view shows an object at (clear ones)
  int64_t wrong = 0;          // wrong pixels involving an object
  int64_t fringe = 0;         // revealed pixels that show a nearer surface's colour
  int64_t holes = 0;          // pixels no layer covers (an object's ones are also wrong)
  double wrong_share() const { return object_pixels ? double(wrong) / double(object_pixels) : 0.0; }
};

// Scores MPIs of a scene against its exact views. At most 3 surfaces.
class EdgeJudge {
 public:
  EdgeJudge(const EdgeScene& scene, const Camera& camera, const DepthRange& range);
  // `mpi` made from the scene's photo, seen from `pose`; fill_masks: per layer the pixels
  // inpainting invented (MpiResult::fill_masks).
  EdgeScore score(const Mpi& mpi, const std::vector<cv::Mat>& fill_masks, const Pose& pose) const;
  // The exact view at `pose` (what a perfect MPI renders).
  cv::Mat exact_view(const Pose& pose) const;

 private:
  // The MPI with each pixel's colour replaced by its surface shares (channel s: surface s).
  Mpi label_mpi(const Mpi& mpi, const std::vector<cv::Mat>& fill_masks) const;

  Mpi exact_;
  Camera camera_;
  cv::Mat source_weights_;       // CV_32FC3: each surface's share of each photo pixel
  std::vector<cv::Mat> hidden_;  // per surface: CV_32FC1, 1 where a nearer surface hides it in the photo
};

}  // namespace ampi
