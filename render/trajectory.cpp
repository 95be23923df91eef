#include "render/trajectory.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace ampi {
namespace {

struct Quaternion {
  double w, x, y, z;
};

// Shepperd's method: pivot on the largest of the four squared components for accuracy.
Quaternion quaternion_from(const cv::Matx33d& r) {
  const double trace = r(0, 0) + r(1, 1) + r(2, 2);
  Quaternion q;
  if (trace > r(0, 0) && trace > r(1, 1) && trace > r(2, 2)) {
    const double s = 2 * std::sqrt(1 + trace);
    q = {s / 4, (r(2, 1) - r(1, 2)) / s, (r(0, 2) - r(2, 0)) / s, (r(1, 0) - r(0, 1)) / s};
  } else if (r(0, 0) > r(1, 1) && r(0, 0) > r(2, 2)) {
    const double s = 2 * std::sqrt(1 + r(0, 0) - r(1, 1) - r(2, 2));
    q = {(r(2, 1) - r(1, 2)) / s, s / 4, (r(0, 1) + r(1, 0)) / s, (r(0, 2) + r(2, 0)) / s};
  } else if (r(1, 1) > r(2, 2)) {
    const double s = 2 * std::sqrt(1 + r(1, 1) - r(0, 0) - r(2, 2));
    q = {(r(0, 2) - r(2, 0)) / s, (r(0, 1) + r(1, 0)) / s, s / 4, (r(1, 2) + r(2, 1)) / s};
  } else {
    const double s = 2 * std::sqrt(1 + r(2, 2) - r(0, 0) - r(1, 1));
    q = {(r(1, 0) - r(0, 1)) / s, (r(0, 2) + r(2, 0)) / s, (r(1, 2) + r(2, 1)) / s, s / 4};
  }
  return q;
}

cv::Matx33d rotation_from(const Quaternion& q) {
  const double w = q.w, x = q.x, y = q.y, z = q.z;
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

Quaternion slerp(Quaternion a, const Quaternion& b, double s) {
  double dot = a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
  if (dot < 0) {  // q and -q are the same rotation: take the short way round
    a = {-a.w, -a.x, -a.y, -a.z};
    dot = -dot;
  }
  double wa = 1 - s, wb = s;
  if (dot < 0.9995) {  // otherwise nearly parallel: linear blend, renormalised below
    const double angle = std::acos(dot);
    wa = std::sin((1 - s) * angle) / std::sin(angle);
    wb = std::sin(s * angle) / std::sin(angle);
  }
  Quaternion q{wa * a.w + wb * b.w, wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z};
  const double norm = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  return {q.w / norm, q.x / norm, q.y / norm, q.z / norm};
}

// Position along a path's one-way sweep, in [0, 1], of frame k of n. Closed paths end
// where they start, so their last frame stops one step short of s = 1; boomerangs go
// 0 -> 1 -> 0 and loop seamlessly too.
double path_position(int k, int n, bool closed, bool boomerang) {
  if (n <= 1) return 0.0;
  if (boomerang) return 1.0 - std::fabs(1.0 - 2.0 * k / n);
  return closed ? static_cast<double>(k) / n : static_cast<double>(k) / (n - 1);
}

Pose camera_at(const cv::Vec3d& centre) {
  Pose p;
  p.t = -centre;  // R = I: X_new = X - centre
  return p;
}

Pose path_pose(PathKind kind, double s, double travel, double focus_depth) {
  const double angle = 2 * M_PI * s;
  switch (kind) {
    case PathKind::Circle: return camera_at({travel * std::cos(angle), travel * std::sin(angle), 0});
    case PathKind::Swing: return camera_at({travel * std::sin(angle), 0, 0});
    case PathKind::ZoomIn: return camera_at({0, 0, travel * s});
    case PathKind::DollyZoom: {
      // Backing away by d puts the focus plane at focus_depth + d; a focal length scaled
      // by the same ratio keeps its image size.
      Pose p = camera_at({0, 0, -travel * s});
      p.zoom = (focus_depth + travel * s) / focus_depth;
      return p;
    }
  }
  return Pose{};
}

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw std::runtime_error(path + ": " + problem);
}

bool is_number(const cv::FileNode& n) { return n.isInt() || n.isReal(); }

double read_number(const cv::FileNode& node, const std::string& path, const std::string& where) {
  if (!is_number(node)) fail(path, where + " must be a number");
  const double v = static_cast<double>(node);
  if (!std::isfinite(v)) fail(path, where + " must be finite");
  return v;
}

cv::Vec3d read_vec3(const cv::FileNode& node, const std::string& path, const std::string& where) {
  if (!node.isSeq() || node.size() != 3) fail(path, where + " must be a list of 3 numbers");
  cv::Vec3d v;
  for (int i = 0; i < 3; ++i) v[i] = read_number(node[i], path, where);
  return v;
}

Keyframe read_keyframe(const cv::FileNode& node, const std::string& path, int index) {
  const std::string where = "keyframe " + std::to_string(index);
  if (!node.isMap()) fail(path, where + " is not an object");
  Keyframe k;
  if (node["time"].empty()) fail(path, where + " has no \"time\"");
  k.time = read_number(node["time"], path, where + " \"time\"");
  if (!node["t"].empty()) k.pose.t = read_vec3(node["t"], path, where + " \"t\"");
  if (!node["rotation"].empty()) {
    const cv::Vec3d degrees = read_vec3(node["rotation"], path, where + " \"rotation\"");
    // Beyond a turn an angle says nothing new, and a huge one has no finite sine.
    for (int i = 0; i < 3; ++i)
      if (std::abs(degrees[i]) > 360) fail(path, where + " \"rotation\" angles must be within [-360, 360] degrees");
    k.pose.R = rotation_from_degrees(degrees);
  }
  if (!node["zoom"].empty()) {
    k.pose.zoom = read_number(node["zoom"], path, where + " \"zoom\"");
    if (!(k.pose.zoom > 0)) fail(path, where + " \"zoom\" must be positive");
  }
  return k;
}

// OpenCV's parse errors span several lines; the file's name is added by the caller.
std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

}  // namespace

PathKind parse_path_kind(const std::string& name) {
  for (PathKind k : {PathKind::Circle, PathKind::Swing, PathKind::ZoomIn, PathKind::DollyZoom})
    if (name == path_kind_name(k)) return k;
  throw std::invalid_argument("unknown trajectory '" + name +
                              "' (expected circle, swing, zoom-in or dolly-zoom)");
}

const char* path_kind_name(PathKind kind) {
  switch (kind) {
    case PathKind::Circle: return "circle";
    case PathKind::Swing: return "swing";
    case PathKind::ZoomIn: return "zoom-in";
    case PathKind::DollyZoom: return "dolly-zoom";
  }
  return "?";
}

std::vector<Pose> camera_path(const PathOptions& o, const std::vector<Plane>& planes) {
  if (planes.empty()) throw std::invalid_argument("camera path: the MPI has no planes");
  if (o.frames < 1 || o.frames > kMaxPathFrames)
    throw std::invalid_argument("camera path: the frame count must be in [1, " + std::to_string(kMaxPathFrames) + "]");
  if (!(o.fps > 0)) throw std::invalid_argument("camera path: fps must be positive");
  if (!(o.amplitude > 0 && o.amplitude < 1))
    throw std::invalid_argument("camera path: the amplitude must be in (0, 1)");
  if (o.focus_plane < -1 || o.focus_plane >= static_cast<int>(planes.size()))
    throw std::invalid_argument("camera path: focus plane " + std::to_string(o.focus_plane) +
                                " does not exist (the MPI has " + std::to_string(planes.size()) + ")");
  double nearest = planes[0].depth;
  for (const Plane& p : planes) nearest = std::min(nearest, p.depth);
  const double focus = o.focus_plane < 0 ? nearest : planes[o.focus_plane].depth;
  const bool closed = o.kind == PathKind::Circle || o.kind == PathKind::Swing;
  const bool boomerang = o.boomerang.value_or(!closed);
  std::vector<Pose> poses;
  poses.reserve(o.frames);
  for (int k = 0; k < o.frames; ++k)
    poses.push_back(path_pose(o.kind, path_position(k, o.frames, closed, boomerang), o.amplitude * nearest, focus));
  return poses;
}

Pose interpolate(const Pose& a, const Pose& b, double s) {
  Pose p;
  p.t = a.t * (1 - s) + b.t * s;
  p.zoom = a.zoom * (1 - s) + b.zoom * s;
  p.R = rotation_from(slerp(quaternion_from(a.R), quaternion_from(b.R), s));
  return p;
}

std::vector<Keyframe> read_keyframes(const std::string& path) {
  // Checked first: FileStorage would also log its own complaint to stderr.
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error) || !std::ifstream(path))
    fail(path, "cannot open the keyframe file");
  cv::FileStorage fs;
  try {
    if (!fs.open(path, cv::FileStorage::READ | cv::FileStorage::FORMAT_JSON))
      fail(path, "cannot open the keyframe file");
  } catch (const cv::Exception& e) {
    fail(path, "not a valid JSON keyframe file (" + first_line(e.err) + ")");
  }
  const cv::FileNode list = fs["keyframes"];
  if (!list.isSeq() || list.size() == 0) fail(path, "needs a non-empty \"keyframes\" list");
  std::vector<Keyframe> keyframes;
  for (int i = 0; i < static_cast<int>(list.size()); ++i) {
    keyframes.push_back(read_keyframe(list[i], path, i));
    if (i > 0 && !(keyframes[i].time > keyframes[i - 1].time))
      fail(path, "keyframe " + std::to_string(i) + " \"time\" must be later than the one before");
  }
  return keyframes;
}

std::vector<Pose> keyframe_path(const std::vector<Keyframe>& keyframes, double fps) {
  if (keyframes.empty()) throw std::invalid_argument("keyframe path: no keyframes");
  if (!(fps > 0)) throw std::invalid_argument("keyframe path: fps must be positive");
  const double start = keyframes.front().time, duration = keyframes.back().time - start;
  // The small allowance keeps a last keyframe at an exact multiple of 1/fps despite rounding.
  const double steps = std::floor(duration * fps + 1e-6);
  if (!(steps < kMaxPathFrames))
    throw std::invalid_argument("keyframe path: " + std::to_string(duration) + " s at " +
                                std::to_string(fps) + " fps is more than " +
                                std::to_string(kMaxPathFrames) + " frames");
  const int frames = static_cast<int>(steps) + 1;
  std::vector<Pose> poses;
  poses.reserve(frames);
  size_t segment = 0;
  for (int k = 0; k < frames; ++k) {
    const double time = start + k / fps;
    while (segment + 2 < keyframes.size() && time > keyframes[segment + 1].time) ++segment;
    if (keyframes.size() == 1) {
      poses.push_back(keyframes[0].pose);
      continue;
    }
    const Keyframe &a = keyframes[segment], &b = keyframes[segment + 1];
    poses.push_back(interpolate(a.pose, b.pose, std::clamp((time - a.time) / (b.time - a.time), 0.0, 1.0)));
  }
  return poses;
}

}  // namespace ampi
