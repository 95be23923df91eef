// One place that turns a weight file into a network. Every network file names its
// architecture in the metadata key `arch` (weights_format/SPEC.md); the loader reads it
// and builds the network of that architecture, so code that takes "a depth model" runs
// every depth family the build knows, and a file of another kind or an unknown
// architecture ends in one line naming the file and what it holds.
#pragma once
#include <memory>
#include <string>

#include "kernels/kernel_table.h"
#include "nets/depth_model.h"
#include "nets/inpaint_net.h"
#include "weights_format/weight_file.h"

namespace ampi {

enum class ModelKind { Depth, Inpaint };

// The kind of network `file` holds, from its `arch`. Throws std::runtime_error
// "PATH: ..." when the key is missing or names an architecture this build does not run.
ModelKind model_kind(const WeightFile& file);

// The model's name as its file gives it: a depth network's variant ("lite", "heavy"),
// what `--model` asks for. Throws like model_kind.
std::string model_name(const WeightFile& file);

// The depth network of any depth architecture; throws "PATH: ..." for anything else.
std::unique_ptr<DepthModel> load_depth_model(const WeightFile& file, const KernelTable& table = kernels());
std::unique_ptr<DepthModel> load_depth_model(const std::string& path, const KernelTable& table = kernels());

// The inpainting network; throws "PATH: ..." for a file of another kind.
InpaintNet load_inpaint_net(const std::string& path, const KernelTable& table = kernels());

}  // namespace ampi
