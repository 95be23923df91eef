// OpenCV's DNN module (Debian's OpenCV, its own CPU backend) running the ONNX export of a
// depth network: one of the peers bench/peers/run.sh puts beside `ampi bench network`.
// Same protocol as the other peers (bench/peers/README.md): reads a 1 x 3 x H x W float32
// .npy input, prints one JSON line per thread count, saves the output as H x W .npy.
//
//   ampi_peer_opencv_dnn --model lite.onnx --input rgb_nchw.npy --threads 1,2 --runs 5 --save out/opencv
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/tensor.h"
#include "weights_format/npy.h"

namespace {

const char kUsage[] =
    "usage: ampi_peer_opencv_dnn --model NET.onnx --input RGB_NCHW.npy [--threads LIST]\n"
    "                            [--runs N] [--warmup N] [--save PREFIX]\n"
    "       ampi_peer_opencv_dnn --version   (OpenCV's version)\n";

struct Options {
  std::string model, input, save;
  std::vector<int> threads{1, 2};
  int runs = 5, warmup = 1;
};

std::vector<int> parse_counts(const std::string& text) {
  std::vector<int> counts;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const int n = std::atoi(item.c_str());
    if (n < 1 || std::to_string(n) != item) throw std::runtime_error("--threads: bad list '" + text + "'");
    counts.push_back(n);
  }
  return counts;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string name = argv[i];
    if (i + 1 >= argc) throw std::runtime_error(name + ": needs a value");
    const std::string value = argv[++i];
    if (name == "--model") o.model = value;
    else if (name == "--input") o.input = value;
    else if (name == "--save") o.save = value;
    else if (name == "--threads") o.threads = parse_counts(value);
    else if (name == "--runs") o.runs = std::max(1, std::atoi(value.c_str()));
    else if (name == "--warmup") o.warmup = std::max(0, std::atoi(value.c_str()));
    else throw std::runtime_error("unknown option " + name);
  }
  if (o.model.empty() || o.input.empty()) throw std::runtime_error("--model and --input are required");
  return o;
}

// The input as a 4-D blob [1][3][H][W] (a copy: the Mat owns its memory).
cv::Mat read_blob(const std::string& path) {
  const ampi::Tensor t = ampi::read_npy(path);
  if (t.rank() != 4 || t.dim(0) != 1 || t.dim(1) != 3)
    throw std::runtime_error(path + ": expected a 1 x 3 x H x W array, got " + ampi::shape_str(t.shape()));
  const int dims[4] = {1, 3, int(t.dim(2)), int(t.dim(3))};
  cv::Mat blob(4, dims, CV_32F);
  std::memcpy(blob.ptr<float>(), t.f32(), t.bytes());
  return blob;
}

void save_output(const cv::Mat& out, const std::string& path) {
  const int h = out.size[out.dims - 2], w = out.size[out.dims - 1];
  if (out.total() != size_t(h) * w) throw std::runtime_error("the network's output is not 1 x 1 x H x W");
  ampi::Tensor t = ampi::Tensor::empty({h, w});
  std::memcpy(t.f32(), out.ptr<float>(), t.bytes());
  ampi::write_npy(path, t);
}

void run(const Options& o) {
  const cv::Mat blob = read_blob(o.input);
  cv::dnn::Net net = cv::dnn::readNetFromONNX(o.model);
  net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  for (int threads : o.threads) {
    cv::setNumThreads(threads);
    cv::Mat out;
    for (int i = 0; i < o.warmup; ++i) {
      net.setInput(blob);
      out = net.forward();
    }
    std::ostringstream line;
    line << "{\"engine\": \"opencv-dnn\", \"threads\": " << threads << ", \"ms\": [";
    for (int i = 0; i < o.runs; ++i) {
      const auto start = std::chrono::steady_clock::now();
      net.setInput(blob);
      out = net.forward();
      line << (i ? ", " : "")
           << std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }
    line << "]}";
    std::printf("%s\n", line.str().c_str());
    std::fflush(stdout);
    if (!o.save.empty()) save_output(out, o.save + ".t" + std::to_string(threads) + ".npy");
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && (!std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h"))) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  if (argc == 2 && !std::strcmp(argv[1], "--version")) {
    std::printf("%s\n", CV_VERSION);
    return 0;
  }
  try {
    run(parse(argc, argv));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ampi_peer_opencv_dnn: %s\n", e.what());
    return 1;
  }
}
