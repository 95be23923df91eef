// Camera paths for parallax videos: the moves users know from 3D-photo tools, and
// keyframe files for anything else.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "mpi/mpi.h"
#include "render/pose.h"

namespace ampi {

enum class PathKind {
  Circle,     // the camera circles in the image plane (x and y)
  Swing,      // the camera sways left and right
  ZoomIn,     // the camera moves towards the scene
  DollyZoom,  // the camera backs away while zooming so the focus plane keeps its size
};

// "circle", "swing", "zoom-in", "dolly-zoom"; throws std::invalid_argument otherwise.
PathKind parse_path_kind(const std::string& name);
const char* path_kind_name(PathKind kind);

struct PathOptions {
  PathKind kind = PathKind::Circle;
  int frames = 90;
  double fps = 30;
  // How far the camera travels, as a fraction of the nearest plane's depth (the nearest
  // layer then moves by about amplitude * fx pixels). In (0, 1): the camera stays in front
  // of every plane.
  double amplitude = 0.05;
  // Back and forth (a seamless loop for the open paths); unset: the path's default, which
  // is one way for the closed paths (circle, swing) and boomerang for the others.
  std::optional<bool> boomerang;
  // Dolly-zoom: the plane whose size stays fixed (index into Mpi::planes); -1: the nearest.
  int focus_plane = -1;
};

// The longest path either kind of path may have (an hour at about 28 fps).
constexpr int kMaxPathFrames = 100000;

// One pose per frame; throws std::invalid_argument naming a bad option.
std::vector<Pose> camera_path(const PathOptions& options, const std::vector<Plane>& planes);

// A pose at a time, from a keyframe file.
struct Keyframe {
  double time = 0;  // seconds, strictly increasing along the file
  Pose pose;
};

// Reads a JSON keyframe file (OpenCV FileStorage):
//   {"keyframes": [{"time": 0, "t": [0, 0, 0], "rotation": [0, 0, 0], "zoom": 1}, ...]}
// "t" is the pose's translation (X_new = R X + t, scene units: those of the plane depths),
// "rotation" degrees about x, y, z, each within [-360, 360] (see rotation_from_degrees),
// "zoom" the focal length factor; all three are optional (identity). Throws
// std::runtime_error with one line naming the file and the problem.
std::vector<Keyframe> read_keyframes(const std::string& path);

// Frames at `fps` from the first keyframe's time to the last's: translation and zoom
// interpolated linearly, rotation by quaternion slerp.
std::vector<Pose> keyframe_path(const std::vector<Keyframe>& keyframes, double fps);

// Linear interpolation of two poses (t and zoom linear, rotation by slerp), s in [0, 1].
Pose interpolate(const Pose& a, const Pose& b, double s);

}  // namespace ampi
