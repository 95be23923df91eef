// Photo to adaptive MPI: depth, slicing, assembly at the photo's full resolution, and
// inpainting of the occluded margins. The stages of `ampi run` before any output is
// written; `ampi bench pipeline` times the same calls.
#pragma once
#include <memory>
#include <optional>
#include <string>

#include "inpaint/mpi_inpaint.h"
#include "mpi/mpi.h"
#include "nets/depth_model.h"
#include "pipeline/progress.h"
#include "slicing/adaptive.h"
#include "slicing/depth_edges.h"

namespace ampi {

struct MpiOptions {
  std::string depth_model = "lite";  // bundled weights/depth_<model>.ampw
  std::string depth_weights;         // a weight file instead of the bundled one
  std::string depth_file;            // the user's own depth map instead of the network
  bool depth_is_distance = false;    // depth_file holds distances (larger = farther)
  // The depth network's working size (DepthModel::set_working_size: the long side for
  // lite and heavy, the input's shorter side for Depth Anything V2); 0: the weight
  // file's. The slicer runs at this size too (as a long side), at most 1024.
  int working_size = 0;
  bool uniform = false;              // the paper's baseline instead of adaptive slicing
  SlicingParams slicing;             // max_planes, the paper's constants, depth range
  double soft_alpha = 0;             // alpha ramp across plane cuts (0 = the paper)
  // Depth edges that follow the photo (slicing/depth_edges.h): the map's soft ramps
  // become steps on the photo's colour edges before slicing, and the layers' borders at
  // those edges are cleaned (feather_depth_edges, edge_feather pixels wide). Off: the map
  // is enlarged bilinearly and sliced as it is, as the paper does.
  bool snap_depth_edges = true;
  DepthEdgeParams depth_edges;
  int edge_feather = 2;
  bool keep_fill_masks = false;      // MpiResult::fill_masks (for evaluations)
  // Which filler invents the occluded margins. The network by default: on held-out photos
  // it scores above Telea and Navier-Stokes (training/INPAINT.md). The harmonic fill alone
  // scores the same PSNR (the network adds texture); push-pull is the fastest.
  Inpainter inpainter = Inpainter::Network;
  std::string inpaint_weights;       // the network's weight file (implies the network)
  double fov_degrees = 60;           // assumed horizontal field of view of the photo
  // A photo whose long side is larger is made into an MPI at this size (depth,
  // slicing, layers, inpainting, and the video and viewer drawn from them), and only its
  // written layers are at the photo's full resolution, made one at a time
  // (pipeline/full_resolution.h): memory stays that of a photo this size plus a few
  // bytes per photo pixel. 0: no cap.
  int max_working_side = 3840;
};

// The filler `kind` names; the network from `weights`, or the bundled
// weights/inpaint.ampw when empty.
LayerFiller make_layer_filler(Inpainter kind, const std::string& weights = "");

struct MpiResult {
  cv::Mat disparity;  // CV_32FC1 at the MPI's size, larger = nearer
  Mpi mpi;            // inpainted; at the photo's size unless the photo was reduced
  std::string inpainter;  // which filler ran: inpainter_name
  std::vector<cv::Mat> fill_masks;  // with keep_fill_masks: per layer, the pixels inpainting invented
  cv::Size slicing_size;  // the map the slicer ran on (the depth network's working size)
  // Set only when the photo was larger than max_working_side: the photo itself and its
  // camera, from which full_resolution.h makes the written layers.
  cv::Mat full_bgr;
  Camera full_camera;
};

// Holds what is loaded once and reused across photos (the networks).
class MpiMaker {
 public:
  explicit MpiMaker(MpiOptions options);
  ~MpiMaker();
  const MpiOptions& options() const { return options_; }

  // bgr: the decoded photo (pipeline/photo_io.h). `photo_path` names it in errors.
  MpiResult make(const cv::Mat& bgr, const std::string& photo_path, Progress& progress);

  // The stages after depth, from a disparity map of the photo's size or smaller (the
  // depth network's working size): depth edges, slicing, assembly, inpainting. bgr is
  // the photo at the MPI's size (no reduction here); the evaluations call this with
  // disparity maps of their own.
  MpiResult make_from_disparity(const cv::Mat& bgr, const cv::Mat& disparity, Progress& progress);

 private:
  cv::Mat working_disparity(const cv::Mat& bgr, cv::Size photo_size, const std::string& photo_path,
                            Progress& progress);
  std::vector<Plane> slice(const cv::Mat& disparity, cv::Size depth_size, MpiResult& result) const;
  LayerFiller& filler();

  MpiOptions options_;
  std::unique_ptr<DepthModel> depth_net_;
  std::optional<LayerFiller> filler_;
  std::string inpainter_;
};

}  // namespace ampi
