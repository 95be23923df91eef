// viewer.html: a standalone page (no network, works from a local file) that shows an MPI
// with parallax following the mouse, a finger or the device's tilt. Each layer is an
// image drawn through its plane homography as a CSS matrix3d, the same
// H = K_new (R + t n^T / z) K^-1 the renderer uses (R = I: the viewer translates and
// zooms), so the browser's compositor does the warping and the blending.
//
// A pose given in the address fixes the view and turns the interaction off, e.g.
// viewer.html#pose=0.05,0,0&zoom=1 (t as in Pose); this is how the tests compare a
// screenshot with the renderer.
#pragma once
#include <string>

#include "mpi/mpi.h"

namespace ampi {

struct ViewerOptions {
  // true: the layers are PNG data URIs inside the page, which then travels alone;
  // false: the page refers to layer_XX.png files in `layer_folder`, relative to itself.
  bool embed_layers = true;
  std::string layer_folder = "mpi";
  // Camera travel at the window's edge, as a fraction of the nearest plane's depth.
  double amplitude = 0.05;
};

// The page's text.
std::string viewer_html(const Mpi& mpi, const ViewerOptions& options = {});

// Writes viewer.html beside the MPI folder: into the parent of `dir` when `dir` is an MPI
// folder itself (it holds mpi.json; referenced layers are then looked up in it whatever
// options.layer_folder says), otherwise into `dir`. The file is written under a
// temporary name and renamed. With referenced layers, each layer_XX.png must exist.
// Returns the page's path; throws std::runtime_error "PATH: problem".
std::string write_viewer(const Mpi& mpi, const std::string& dir, const ViewerOptions& options = {});

}  // namespace ampi
