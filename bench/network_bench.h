// ampi bench network: DepthModel::run alone on a given image, so that the peer benchmark
// (bench/peers/run.sh) can put ampi beside ONNX Runtime, OpenCV DNN and PyTorch running
// the same network on the same pixels.
#pragma once
#include <string>
#include <vector>

namespace ampi::bench {

struct NetworkBenchOptions {
  std::string input;                // RGB.npy: H x W x 3 float32 in [0, 1]; required
  std::string model = "lite";       // a bundled depth model by name
  std::string weights;              // a depth weight file instead of the bundled model
  std::vector<int> threads = {1, 2};  // one timing line per thread count
  int runs = 5;                     // timed runs per thread count
  int warmup = 1;                   // untimed runs first (the first plans the arena)
  std::string save;                 // writes the output to SAVE.tT.npy per count T if set
};

// Prints one JSON line per thread count (what bench/peers/run_peers.py reads):
//   {"engine": "ampi", "model": ..., "isa": ..., "threads": T, "ms": [...]}
// and on stderr how much loading raised the resident peak, beside the file's size.
// Throws std::runtime_error for a missing input or an unreadable file.
int network_benchmark(const NetworkBenchOptions& options);

}  // namespace ampi::bench
