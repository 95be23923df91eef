// libFuzzer target: the MPI folder loader (read_mpi). The input is the folder's
// mpi.json; the folder also holds two valid 4x3 RGBA layers, layer_00.png and
// layer_01.png, so inputs that describe them get past the JSON checks into the layer
// checks.
#include <cstdint>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>

#include "fuzz/fuzz_support.h"
#include "mpi/mpi_io.h"

using ampi::fuzz::require;

namespace {

void write_layers(const std::string& dir) {
  for (const char* name : {"layer_00.png", "layer_01.png"}) {
    const cv::Mat layer(3, 4, CV_8UC4, cv::Scalar(10, 20, 30, 255));
    require(cv::imwrite(dir + "/" + name, layer), "cannot write a layer");
  }
}

// What read_mpi promises of an MPI it returns.
void check_mpi(const ampi::Mpi& mpi) {
  require(!mpi.planes.empty() && mpi.layers.size() == mpi.planes.size(), "one layer per plane");
  for (size_t j = 0; j < mpi.planes.size(); ++j) {
    require(mpi.planes[j].depth > 0, "plane depth not positive");
    require(j == 0 || mpi.planes[j].depth < mpi.planes[j - 1].depth, "planes not back to front");
    const cv::Mat& layer = mpi.layers[j];
    require(layer.type() == CV_8UC4 && layer.cols == mpi.camera.width && layer.rows == mpi.camera.height,
            "layer not W x H RGBA");
  }
  require(mpi.camera.fx > 0 && mpi.camera.fy > 0, "focal lengths not positive");
  require(mpi.range.near > 0 && mpi.range.far > mpi.range.near, "depth range not 0 < near < far");
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ampi::fuzz::init_target();
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  write_layers(ampi::fuzz::scratch_dir());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ampi::fuzz::write_scratch_file("mpi.json", data, size);
  try {
    check_mpi(ampi::read_mpi(ampi::fuzz::scratch_dir()));
  } catch (const std::runtime_error&) {
    // A rejected folder.
  }
  return 0;
}
