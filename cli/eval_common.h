// What the modes of `ampi eval` share: finding photos, scaling them, and the modes that
// live in files of their own.
#pragma once
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace ampi::cli {

// Every .jpg, .jpeg and .png under dir, recursively, sorted. Throws std::runtime_error
// "DIR: not a directory" or "DIR: no ... photos".
std::vector<std::string> list_images(const std::string& dir);

// The photo scaled down (INTER_AREA) to at most max_side on its long side.
cv::Mat fit_long_side(const cv::Mat& bgr, int max_side);

// ampi eval edges (cli/cmd_eval_edges.cpp).
int eval_edges(int argc, char** argv);

}  // namespace ampi::cli
