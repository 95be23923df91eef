// MPI folders on disk: layer_00.png ... (RGBA PNG, back to front) and mpi.json, the
// description every tool that reads an MPI relies on. mpi.json, format version 1:
//
//   { "format": "ampi-mpi", "version": 1, "width": W, "height": H,
//     "camera": { "fx": .., "fy": .., "cx": .., "cy": .. },
//     "near": .., "far": .., "plane_count": N,
//     "planes": [ { "depth": .., "disparity": .., "interval": [lo, hi], "pixels": n,
//                   "layer": "layer_00.png" }, ... ] }   (back to front)
//
// depth is the plane's distance z (decreasing from back to front), disparity its
// normalised disparity 0..255, interval the normalised disparities it was cut from
// (see slicing/adaptive.h), pixels how many source pixels it took.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "mpi/mpi.h"

namespace ampi {

constexpr int kMpiFormatVersion = 1;

// Writes the layers and then mpi.json into `dir` (created if missing). Each file is
// written as NAME.tmp and renamed, so a reader never sees half a file; nothing already
// in `dir` is deleted. Throws std::runtime_error "PATH: problem" for an inconsistent Mpi
// or a file that cannot be written.
void write_mpi(const Mpi& mpi, const std::string& dir);

// The same for an MPI too large to hold at once: `description` (camera, range, planes;
// its layers are ignored) and layer(j), called once per plane in order, each layer
// encoded and dropped before the next is made.
void write_mpi_streamed(const Mpi& description, const std::function<cv::Mat(size_t)>& layer,
                        const std::string& dir);

// Reads and validates an MPI folder. Every problem (missing folder or mpi.json,
// malformed JSON, other format or version, missing or ill-typed field, plane count
// mismatch, missing or unreadable layer, layer not 8-bit RGBA or not W x H, planes not
// back to front, non-positive depth, bad intrinsics or range) is one
// std::runtime_error "PATH: problem".
Mpi read_mpi(const std::string& dir);

// Writes `bytes` to `path` through `path`.tmp and a rename. Throws std::runtime_error
// "PATH: problem".
void write_file_atomic(const std::string& path, const std::vector<unsigned char>& bytes);

}  // namespace ampi
