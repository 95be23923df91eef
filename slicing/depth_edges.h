// Depth edges that follow the photo. A depth network's map is soft at object boundaries:
// it runs at a fraction of the photo's size and is enlarged, so between a near object and
// what is behind it lies a ramp of in-between disparities. Sliced as it is, the ramp
// becomes geometry: a plane inside it carries the object's rim, which then moves at its
// own speed and tears the object apart in every new view.
//
// snap_depth_edges brings the map to the photo's resolution and turns every such ramp
// into a step placed on the photo's colour edge:
//   1. At a fitting size (the map's own when it is smaller than the photo, else the photo
//      reduced to guide_long_side), the guided filter (He, Sun and Tang, "Guided Image
//      Filtering", ECCV 2010 / TPAMI 2013; the colour form) fits the disparity in every
//      window of side 2 radius + 1 as a linear function of the photo's colour:
//      d ~ mean(d) + a . (colour - mean(colour)). Its coefficients, enlarged to the
//      photo's size (the "fast guided filter" way of upsampling, He and Sun 2015), say
//      how far each full-resolution pixel's own colour moves its disparity.
//   2. The local extremes of the disparity over the same windows (lo, hi) say where a
//      depth edge is: hi - lo of at least min_step levels of the 0..255 map, and not
//      much less than over windows twice as wide (a slope, such as a ground plane,
//      spreads twice as much there; a step the same); the pixels within a window of
//      such an edge's core are near it.
//   3. A pixel near such an edge whose disparity d lies strictly inside the ramp takes
//      the extreme of the side d and its colour point to: hi if d + a . (colour -
//      mean(colour)) is at least (lo + hi) / 2, else lo. Where colour tells the sides
//      apart it decides; where it does not, the ramp is split at its middle. Every other
//      pixel keeps its disparity, so where the map has no edge (or its edges are
//      already sharp) nothing changes.
// The result has two sides and nothing between them wherever a ramp was, so the slicer
// finds the two surfaces as two planes whatever the ramp's width, and the object's rim
// travels with the object.
#pragma once
#include <opencv2/core.hpp>

#include "engine/isa.h"

namespace ampi {

struct DepthEdgeParams {
  // A map already at the photo's size is fitted on a reduced copy with at most this long
  // side: the soft ramps of a network's map are a few of its own pixels wide, so nothing
  // finer is needed to find them, and the windows stay small.
  int guide_long_side = 512;
  // Window radius at the fitting size, in its pixels. The window must span a ramp for lo
  // and hi to reach both surfaces. 0: a 64th of the long side for a map smaller than the
  // photo (4 px at 256), a 32nd for one of the photo's size (16 at 512: it may have been
  // enlarged from a fraction of it), at least 2.
  int radius = 0;
  // The guided filter's regulariser as a colour standard deviation (colour in [0, 1]):
  // colour variations much smaller than this within a window do not predict disparity.
  double color_sigma = 0.03;
  double min_step = 16;       // levels of the 0..255 map: a smaller local spread is no edge
  // An edge's core: a window whose spread is at least this share of the spread over a
  // window twice as wide. A slope's grows in proportion (share 0.5), a step's does not
  // (share 1), so a ground plane is never taken for an edge, however steep. Pixels
  // within a window of a core are near the edge.
  double min_growth_share = 0.7;
  // A pixel within this fraction of the spread from lo or hi already sits on a surface
  // and keeps its value. 0: only the exact extremes do, so no in-between value is left
  // for the slicer to make a plane of.
  double ramp_margin = 0.0;
};

struct DepthEdges {
  cv::Mat disparity;  // CV_32FC1 at the photo's size, ramps snapped to colour edges
  cv::Mat band;       // CV_8UC1 at the photo's size: 255 where a depth edge is near
};

// bgr: the photo (CV_8UC3); disparity: CV_32FC1, finite, larger = nearer, of the photo's
// size or smaller (a network's working size; it is enlarged bilinearly as cv::resize
// does). isa: which row kernel variant runs (tests force each). Throws
// std::invalid_argument for bad inputs or params.
DepthEdges snap_depth_edges(const cv::Mat& bgr, const cv::Mat& disparity, const DepthEdgeParams& params = {},
                            Isa isa = active_isa());

// The disparity enlarged to the photo's size as before snapping existed: bilinear, the
// map as it is where it already has the photo's size.
cv::Mat enlarge_disparity(const cv::Mat& disparity, cv::Size size);

}  // namespace ampi
