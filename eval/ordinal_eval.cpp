#include "eval/ordinal_eval.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include <opencv2/core/persistence.hpp>

namespace ampi {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw std::runtime_error(path + ": " + problem);
}

std::string read_string(const cv::FileNode& node, const char* key, const std::string& where) {
  const cv::FileNode v = node[key];
  if (!v.isString()) fail(where, std::string("'") + key + "' missing or not a string");
  return v.string();
}

cv::Point2f read_point(const cv::FileNode& node, const char* key, const std::string& where) {
  const cv::FileNode v = node[key];
  const auto number = [](const cv::FileNode& n) { return n.isReal() || n.isInt(); };
  if (!v.isSeq() || v.size() != 2 || !number(v[0]) || !number(v[1]))
    fail(where, std::string("'") + key + "' is not a point [x, y]");
  return {float(v[0].real()), float(v[1].real())};
}

int read_label(const cv::FileNode& pair, const std::string& where) {
  const std::string label = read_string(pair, "label", where);
  if (label == "A") return 1;
  if (label == "B") return -1;
  if (label == "=") return 0;
  fail(where, "label '" + label + "' is not A, B or =");
}

OrdinalPhoto read_photo_entry(const cv::FileNode& node, const std::string& path) {
  OrdinalPhoto photo;
  photo.photo = read_string(node, "photo", path);
  const std::string where = path + ": " + photo.photo;
  photo.split = read_string(node, "split", where);
  if (photo.split != "train" && photo.split != "val" && photo.split != "test" && photo.split != "holdout")
    fail(where, "split '" + photo.split + "' is not train, val, test or holdout");
  if (!node["width"].isInt() || !node["height"].isInt() || int(node["width"]) < 1 || int(node["height"]) < 1)
    fail(where, "width and height must be positive integers");
  photo.size = {int(node["width"]), int(node["height"])};
  const cv::FileNode pairs = node["pairs"];
  if (!pairs.isSeq()) fail(where, "'pairs' missing or not a list");
  const cv::Rect2f inside(0, 0, float(photo.size.width), float(photo.size.height));
  for (const cv::FileNode& p : pairs) {
    OrdinalPair pair{read_point(p, "a", where), read_point(p, "b", where), read_label(p, where)};
    if (!inside.contains(pair.a) || !inside.contains(pair.b)) fail(where, "a point lies outside the photo");
    photo.pairs.push_back(pair);
  }
  return photo;
}

// Bilinear sample at a point of the labelled photo, mapped to the map's own size
// (pixel centres aligned, as cv::resize with INTER_LINEAR maps them).
float sample(const cv::Mat& map, cv::Point2f p, cv::Size photo) {
  const float x = std::clamp((p.x + 0.5f) * map.cols / photo.width - 0.5f, 0.0f, float(map.cols - 1));
  const float y = std::clamp((p.y + 0.5f) * map.rows / photo.height - 0.5f, 0.0f, float(map.rows - 1));
  const int x0 = int(x), y0 = int(y);
  const int x1 = std::min(x0 + 1, map.cols - 1), y1 = std::min(y0 + 1, map.rows - 1);
  const float fx = x - x0, fy = y - y0;
  const float top = map.at<float>(y0, x0) * (1 - fx) + map.at<float>(y0, x1) * fx;
  const float bottom = map.at<float>(y1, x0) * (1 - fx) + map.at<float>(y1, x1) * fx;
  return top * (1 - fy) + bottom * fy;
}

}  // namespace

std::vector<OrdinalPhoto> read_ordinal_set(const std::string& path) {
  // A missing file is caught here: OpenCV would log a line of its own before failing.
  if (!std::filesystem::is_regular_file(path)) fail(path, "cannot open");
  cv::FileStorage fs;
  try {
    if (!fs.open(path, cv::FileStorage::READ | cv::FileStorage::FORMAT_JSON)) fail(path, "cannot open");
  } catch (const cv::Exception&) {
    fail(path, "not a valid JSON ordinal set");
  }
  const cv::FileNode photos = fs["photos"];
  if (!photos.isSeq()) fail(path, "'photos' missing or not a list");
  std::vector<OrdinalPhoto> set;
  for (const cv::FileNode& node : photos) {
    if (!node.isMap()) fail(path, "an entry of 'photos' is not an object");
    set.push_back(read_photo_entry(node, path));
  }
  if (set.empty()) fail(path, "no photos");
  return set;
}

OrdinalScore score_ordinal(const cv::Mat& disparity, const OrdinalPhoto& photo) {
  if (disparity.type() != CV_32FC1 || disparity.empty())
    throw std::invalid_argument("score_ordinal: the disparity map must be a non-empty CV_32FC1");
  OrdinalScore score;
  for (const OrdinalPair& pair : photo.pairs) {
    if (pair.a_nearer == 0) continue;
    const float a = sample(disparity, pair.a, photo.size), b = sample(disparity, pair.b, photo.size);
    const int predicted = a > b ? 1 : a < b ? -1 : 0;
    score.wrong += predicted == 0 ? 0.5 : predicted != pair.a_nearer ? 1.0 : 0.0;
    ++score.pairs;
  }
  return score;
}

}  // namespace ampi
