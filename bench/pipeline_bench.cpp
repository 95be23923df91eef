#include "bench/pipeline_bench.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "bench/bench.h"
#include "engine/thread_pool.h"
#include "mpi/mpi_io.h"
#include "nets/bundled_weights.h"
#include "nets/model_loader.h"
#include "pipeline/depth_estimate.h"
#include "pipeline/full_resolution.h"
#include "pipeline/photo_io.h"
#include "pipeline/video.h"
#include "slicing/adaptive.h"

namespace fs = std::filesystem;

namespace ampi::bench {
namespace {

struct SizeResult {
  cv::Size size;
  std::vector<std::string> stages;             // in pipeline order
  std::map<std::string, std::vector<double>> ms;  // per stage, one value per run
  std::map<std::string, double> stage_peak_mb;    // per stage, the largest over all runs
  double peak_mb = 0;                             // the largest of any stage
  // The ffmpeg process that encodes the MP4 (render/video_out.h), the largest over all
  // runs; 0 when OpenCV encodes it inside this process.
  double encoder_peak_mb = 0;
  size_t planes = 0;
  cv::Size slicing_size;  // where the depth network's output was sliced
  // The network alone and the slicer, timed alternately and warm (measure_slicing_share).
  double warm_network_ms = 0, warm_slicing_ms = 0;
  // Photo to MPI alone (nothing written), with depth edges and with --no-edge-snap, taken
  // in turns after every measured run.
  std::vector<double> to_mpi_ms, to_mpi_plain_ms;
};

// The stages from the photo file to the inpainted MPI.
const char* const kToMpi[] = {"decode", "reduce", "depth", "depth edges", "slicing", "assembly", "inpainting"};

double to_mpi_sum(const Progress& progress) {
  double sum = 0;
  for (const auto& [stage, ms] : progress.times_ms())
    for (const char* s : kToMpi) sum += stage == s ? ms : 0;
  return sum;
}

// Photo to MPI only, as `ampi run` does it before writing anything.
double time_to_mpi(MpiMaker& maker, const std::string& photo_file) {
  Progress progress(/*quiet=*/true);
  {
    cv::Mat bgr = progress.stage("decode", [&] { return read_photo(photo_file); });
    const MpiResult result = maker.make(bgr, photo_file, progress);
  }
  release_free_memory();
  return to_mpi_sum(progress);
}

struct RunOutcome {
  size_t planes = 0;
  cv::Size slicing_size;
  double encoder_peak_mb = 0;
};

// One `ampi run` worth of work on `photo_file`, timed by stage into `progress`, letting
// buffers go where `ampi run` does.
RunOutcome run_once(MpiMaker& maker, const std::string& photo_file, const fs::path& scratch,
                    const VideoOptions& video, Progress& progress) {
  cv::Mat bgr = progress.stage("decode", [&] { return read_photo(photo_file); });
  MpiResult result = maker.make(bgr, photo_file, progress);
  bgr.release();
  RunOutcome outcome{result.mpi.planes.size(), result.slicing_size};
  fs::remove_all(scratch / "mpi");
  fs::remove_all(scratch / "video.mp4");
  progress.stage("write mpi", [&] { write_mpi_at_photo_size(result, (scratch / "mpi").string()); });
  result.disparity.release();
  result.full_bgr.release();
  const VideoWritten written = progress.stage("render+encode", [&] {
    return write_video(std::move(result.mpi), video, (scratch / "video.mp4").string(), false);
  });
  outcome.encoder_peak_mb = written.encoder_peak_mb;
  release_free_memory();
  return outcome;
}

SizeResult measure(const cv::Mat& source, cv::Size size, int runs, const MpiOptions& options,
                   const VideoOptions& video, const fs::path& scratch) {
  SizeResult r;
  r.size = size;
  cv::Mat resized;
  cv::resize(source, resized, size, 0, 0, size.width < source.cols ? cv::INTER_AREA : cv::INTER_CUBIC);
  const std::string photo_file = (scratch / "photo.jpg").string();
  if (!cv::imwrite(photo_file, resized, {cv::IMWRITE_JPEG_QUALITY, 92}))
    throw std::runtime_error(photo_file + ": cannot write the benchmark photo");
  resized.release();  // not held through the runs, whose memory is measured
  MpiMaker maker{options};
  MpiOptions plain_options = options;
  plain_options.snap_depth_edges = false;
  MpiMaker plain{plain_options};
  for (int k = 0; k <= runs; ++k) {  // run 0 loads the networks and warms the caches
    Progress progress(/*quiet=*/true, /*measure_memory=*/true);
    const RunOutcome outcome = run_once(maker, photo_file, scratch, video, progress);
    r.planes = outcome.planes;
    r.slicing_size = outcome.slicing_size;
    r.encoder_peak_mb = std::max(r.encoder_peak_mb, outcome.encoder_peak_mb);
    // Memory counts every run, the one that loads the networks included.
    for (const auto& [stage, mb] : progress.peaks_mb()) {
      r.stage_peak_mb[stage] = std::max(r.stage_peak_mb[stage], mb);
      r.peak_mb = std::max(r.peak_mb, mb);
    }
    if (k == 0) continue;
    // Alternating which goes first, so neither always follows the other.
    if (k % 2) r.to_mpi_ms.push_back(time_to_mpi(maker, photo_file));
    r.to_mpi_plain_ms.push_back(time_to_mpi(plain, photo_file));
    if (k % 2 == 0) r.to_mpi_ms.push_back(time_to_mpi(maker, photo_file));
    for (const auto& [stage, ms] : progress.times_ms()) {
      if (!r.ms.count(stage)) r.stages.push_back(stage);
      r.ms[stage].push_back(ms);
    }
  }
  return r;
}

// Slicing's cost against the depth network's, like for like: the network alone on the
// photo already shrunk to the working size, and the slicer on its output, each timed
// warm, alternately, `reps` times (medians). The run's stage times differ: there the slicer's buffers are touched
// for the first time after the heap was handed back (page faults), while the network's
// arena persists, and the depth stage includes shrinking the photo.
void measure_slicing_share(const cv::Mat& source, const MpiOptions& options, int reps, SizeResult& r) {
  const std::unique_ptr<DepthModel> net = load_depth_model(depth_weights_path(options.depth_weights, options.depth_model));
  if (options.working_size) set_working_size_option(*net, options.working_size);
  cv::Mat photo, small;
  cv::resize(source, photo, r.size, 0, 0, cv::INTER_AREA);
  const ImageSize work = net->input_size(photo.rows, photo.cols);
  cv::resize(photo, small, {work.width, work.height}, 0, 0, cv::INTER_AREA);
  const int side = 0;  // the size set above
  cv::Mat disparity = estimate_disparity(*net, small, side);
  std::vector<double> network_ms, slicing_ms;
  for (int k = 0; k <= reps; ++k) {  // k = 0 warms up
    const double network = time_ms([&] { disparity = estimate_disparity(*net, small, side); });
    const double slicing = time_ms([&] { slice_adaptive(disparity, options.slicing); });
    if (k == 0) continue;
    network_ms.push_back(network);
    slicing_ms.push_back(slicing);
  }
  r.warm_network_ms = median(network_ms);
  r.warm_slicing_ms = median(slicing_ms);
}

std::string cell(const char* format, double value) {
  char text[48];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

double median_of(const SizeResult& r, const std::string& stage) {
  return r.ms.count(stage) ? median(r.ms.at(stage)) : 0;
}

// Slicing must stay a small part of making the depth: at most this share of the depth
// network's time at the same resolution.
constexpr double kSlicingShareTarget = 0.05;
constexpr int kSlicingShareReps = 30;
// Depth edges that follow the photo must be nearly free: they add at most this share to
// the photo-to-MPI time.
constexpr double kEdgeGrowthTarget = 0.10;

std::string table(const std::vector<SizeResult>& results, const MpiOptions& options, int threads,
                  int frames, int runs) {
  std::ostringstream md;
  md << "# Pipeline benchmark\n\n"
     << "`ampi bench pipeline`: the stages of `ampi run` on the bundled example photo resized\n"
     << "to each size, " << threads << " threads, median of " << runs << " runs after a warm-up run;\n"
     << "the video is " << frames << " frames. Peak memory: the process's maximum resident set\n"
     << "while the stage ran (its peak is reset as each stage starts), the largest over all runs,\n"
     << "the warm-up that loads the networks included. As in `ampi run`, the heap's free\n"
     << "memory is handed back to the system after each photo and after any stage that leaves\n"
     << "64 MB or more free (pipeline/progress.h), outside the stage times. The MP4 is encoded\n"
     << "by the ffmpeg program when it is installed (render/video_out.h), in a process of its\n"
     << "own: its peak, measured when it exits, has its own row. Inpainting: "
     << inpainter_name(options.inpainter) << "; depth network's long side: "
     << (options.working_size ? std::to_string(options.working_size) : std::string("the weight file's"))
     << ". Machine: " << sysconf(_SC_NPROCESSORS_ONLN) << " cores.\n\n"
     << "| stage |";
  for (const SizeResult& r : results)
    md << " " << r.size.width << "x" << r.size.height << " (ms) | peak (MB) |";
  md << "\n|---|";
  for (size_t i = 0; i < results.size(); ++i) md << "---:|---:|";
  md << "\n";
  for (const std::string& stage : results.front().stages) {
    md << "| " << stage << " |";
    for (const SizeResult& r : results)
      md << cell(" %.0f |", median_of(r, stage))
         << cell(" %.0f |", r.stage_peak_mb.count(stage) ? r.stage_peak_mb.at(stage) : 0);
    md << "\n";
  }
  md << "| **photo to MPI** (decode..inpainting) |";
  for (const SizeResult& r : results) {
    double sum = 0, peak = 0;
    for (const char* s : kToMpi) {
      sum += median_of(r, s);
      if (r.stage_peak_mb.count(s)) peak = std::max(peak, r.stage_peak_mb.at(s));
    }
    md << cell(" **%.0f** |", sum) << cell(" %.0f |", peak);
  }
  md << "\n| photo to MPI alone (median) |";
  for (const SizeResult& r : results) md << cell(" %.0f | |", median(r.to_mpi_ms));
  md << "\n| photo to MPI alone, `--no-edge-snap` (median) |";
  for (const SizeResult& r : results) md << cell(" %.0f | |", median(r.to_mpi_plain_ms));
  md << "\n| **depth edges: photo to MPI grows by** (target <= " << cell("%.0f", 100 * kEdgeGrowthTarget) << "%) |";
  for (const SizeResult& r : results) {
    const double growth = median(r.to_mpi_ms) / median(r.to_mpi_plain_ms) - 1;
    md << cell(" %+.1f%%", 100 * growth) << (growth <= kEdgeGrowthTarget ? " (met)" : " (not met)") << " | |";
  }
  md << "\n| **whole run** (peak of any stage) |";
  for (const SizeResult& r : results) md << " |" << cell(" **%.0f** |", r.peak_mb);
  md << "\n| video encoder, its own process (ffmpeg) |";
  for (const SizeResult& r : results) md << " |" << cell(" %.0f |", r.encoder_peak_mb);
  md << "\n| **whole run with the encoder** (render+encode's peak + the encoder's, an upper bound) |";
  for (const SizeResult& r : results) {
    const double video = r.stage_peak_mb.count("render+encode") ? r.stage_peak_mb.at("render+encode") : 0;
    md << " |" << cell(" **%.0f** |", std::max(r.peak_mb, video + r.encoder_peak_mb));
  }
  md << "\n| planes |";
  for (const SizeResult& r : results) md << " " << r.planes << " | |";
  // The slicer runs on the depth network's output, so both work at the same resolution;
  // the depth stage also includes shrinking the photo to it.
  md << "\n| depth and slicing ran at |";
  for (const SizeResult& r : results)
    md << " " << r.slicing_size.width << "x" << r.slicing_size.height << " | |";
  md << "\n| slicing / depth stage, in the run |";
  for (const SizeResult& r : results) {
    const double depth = median_of(r, "depth");
    md << cell(" %.1f%% |", depth > 0 ? 100 * median_of(r, "slicing") / depth : 0) << " |";
  }
  md << "\n| depth network alone, warm (ms) |";
  for (const SizeResult& r : results) md << cell(" %.2f | |", r.warm_network_ms);
  md << "\n| slicing, warm (ms) |";
  for (const SizeResult& r : results) md << cell(" %.3f | |", r.warm_slicing_ms);
  md << "\n| **slicing / depth network, warm** (target <= " << cell("%.0f", 100 * kSlicingShareTarget)
     << "%) |";
  for (const SizeResult& r : results) {
    const double share = r.warm_network_ms > 0 ? r.warm_slicing_ms / r.warm_network_ms : 0;
    md << cell(" %.1f%%", 100 * share) << (share <= kSlicingShareTarget ? " (met)" : " (not met)") << " | |";
  }
  md << "\n\nThe warm rows time the depth network alone (on the photo already shrunk to the\n"
     << "working size) and the slicer on its output alternately, " << kSlicingShareReps
     << " times each, medians: the\nslicer's share of the network's time. In the run, the slicer's buffers are touched for the\n"
     << "first time after the heap was handed back (page faults), while the network's arena\n"
     << "persists, and the depth stage includes shrinking the photo.\n\n"
     << "Depth edges (slicing/depth_edges.h) are on, as in `ampi run`. Their cost: after every\n"
     << "measured run, photo to MPI alone (decode..inpainting, nothing written) with them and\n"
     << "with `--no-edge-snap` (the map enlarged and sliced as it is, no feathering), in turns,\n"
     << "each first every other time; medians over the runs.\n";
  return md.str();
}

}  // namespace

int pipeline_benchmark(const PipelineBenchOptions& o) {
  set_default_threads(o.threads);
  const cv::Mat source = read_photo(o.photo);
  VideoOptions video;
  video.path.frames = o.frames;
  const fs::path scratch = fs::temp_directory_path() / ("ampi_bench_pipeline_" + std::to_string(getpid()));
  fs::create_directories(scratch);
  std::vector<SizeResult> results;
  try {
    for (cv::Size size : o.sizes) {
      std::fprintf(stderr, "ampi bench pipeline: %dx%d ...\n", size.width, size.height);
      results.push_back(measure(source, size, o.runs, o.mpi, video, scratch));
      measure_slicing_share(source, o.mpi, kSlicingShareReps, results.back());
    }
  } catch (...) {
    fs::remove_all(scratch);
    throw;
  }
  fs::remove_all(scratch);
  const std::string md = table(results, o.mpi, o.threads, o.frames, o.runs);
  std::fputs(md.c_str(), stdout);
  std::ofstream(o.out) << md;
  std::fprintf(stderr, "ampi bench pipeline: wrote %s\n", o.out.c_str());
  return 0;
}

}  // namespace ampi::bench
