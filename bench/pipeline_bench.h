// ampi bench pipeline: where the time and the memory of `ampi run` go, stage by stage,
// at 1024x768 and at 4K, on a photo resized to each size.
#pragma once
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/make_mpi.h"

namespace ampi::bench {

struct PipelineBenchOptions {
  std::string photo = "examples/forest_path.jpg";
  std::string out = "bench/RESULTS-pipeline.md";  // the table, also printed
  int runs = 3;     // measured runs per size, after a warm-up run
  int threads = 2;  // worker threads (the default pool's size)
  int frames = 30;  // video frames rendered and encoded per run
  std::vector<cv::Size> sizes = {{1024, 768}, {3840, 2160}};  // the photo is resized to each
  MpiOptions mpi;   // as `ampi run` makes the MPI (the inpainter, the working size)
};

int pipeline_benchmark(const PipelineBenchOptions& options);

}  // namespace ampi::bench
