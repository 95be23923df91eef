// ampi info FILE: what a weight file holds (version, metadata, tensor table, totals).
// Opening the file validates all of it, so a damaged file ends in a one-line error.
#include <algorithm>
#include <array>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/args.h"
#include "cli/commands.h"
#include "nets/model_loader.h"
#include "weights_format/weight_file.h"

namespace ampi::cli {
namespace {

const char kUsage[] =
    "usage: ampi info FILE.ampw\n"
    "\n"
    "Validates a weight file (checksums, bounds, shapes) and prints its format version,\n"
    "metadata, tensor table (name, dtype, shape, bytes) and totals. A depth network's file\n"
    "is also built, and its architecture, variant, parameters (those inference runs) and\n"
    "working size are printed first.\n";

template <size_t N>
void print_table(const std::array<std::string, N>& header, const std::vector<std::array<std::string, N>>& rows) {
  std::array<size_t, N> width{};
  for (size_t c = 0; c < N; ++c) {
    width[c] = header[c].size();
    for (const auto& row : rows) width[c] = std::max(width[c], row[c].size());
  }
  auto print_row = [&](const std::array<std::string, N>& row) {
    std::string line = " ";
    for (size_t c = 0; c < N; ++c) {
      line += " " + row[c];
      if (c + 1 < N) line.append(width[c] - row[c].size(), ' ');
    }
    std::printf("%s\n", line.c_str());
  };
  print_row(header);
  for (const auto& row : rows) print_row(row);
}

// The network a depth file builds, in one line; nothing for other files. A file whose
// network cannot be built is still shown, with the reason.
void print_model(const WeightFile& wf) {
  std::unique_ptr<DepthModel> net;
  try {
    if (!wf.has("arch") || model_kind(wf) != ModelKind::Depth) return;
    net = load_depth_model(wf);
  } catch (const std::exception& e) {
    std::printf("model: cannot be built: %s\n", e.what());
    return;
  }
  std::printf("model: %s, variant %s, %lld parameters, working size %d\n", net->architecture().c_str(),
              net->variant().c_str(), static_cast<long long>(net->parameter_count()), net->working_size());
}

void print_info(const WeightFile& wf) {
  std::printf("%s: AMPW version %d.%d\n", wf.path().c_str(), wf.version_major(), wf.version_minor());
  print_model(wf);

  const auto metadata = wf.metadata_rows();
  std::printf("\nmetadata (%zu entries):\n", metadata.size());
  if (!metadata.empty()) print_table<3>({"key", "type", "value"}, metadata);

  std::vector<std::array<std::string, 4>> tensor_rows;
  int64_t parameters = 0;
  uint64_t bytes = 0;
  for (const TensorInfo& t : wf.tensors()) {
    tensor_rows.push_back({t.name, dtype_name(t.dtype), shape_str(t.shape), std::to_string(t.bytes)});
    parameters += shape_numel(t.shape);
    bytes += t.bytes;
  }
  std::printf("\ntensors (%zu):\n", tensor_rows.size());
  if (!tensor_rows.empty()) print_table<4>({"name", "dtype", "shape", "bytes"}, tensor_rows);
  std::printf("\ntotal: %lld parameters, %llu bytes of tensor data\n", static_cast<long long>(parameters),
              static_cast<unsigned long long>(bytes));
}

}  // namespace

int cmd_info(int argc, char** argv) {
  std::vector<std::string> files;
  ArgParser p("info", kUsage);
  p.positionals(&files);
  if (!p.parse(argc, argv)) return 0;
  if (files.size() != 1) throw std::runtime_error("expected one weight file (usage: ampi info FILE.ampw)");
  print_info(WeightFile::open(files[0]));
  return 0;
}

}  // namespace ampi::cli
