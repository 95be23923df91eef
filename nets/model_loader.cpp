#include "nets/model_loader.h"

#include <stdexcept>

#include "nets/architectures.h"
#include "nets/depth_anything_net.h"
#include "nets/depth_net.h"

namespace ampi {
namespace {

struct Architecture {
  const char* name;
  ModelKind kind;
};

// Every architecture this build runs; a new network family adds its line here and its
// case in the loader of its kind.
constexpr Architecture kArchitectures[] = {
    {arch::kDepthDwtMobileNetV3, ModelKind::Depth},
    {arch::kDepthDinoV2Dpt, ModelKind::Depth},
    {arch::kInpaintGatedConv, ModelKind::Inpaint},
};

const char* kind_name(ModelKind kind) {
  return kind == ModelKind::Depth ? "a depth network" : "an inpainting network";
}

std::string known_names() {
  std::string names;
  for (const Architecture& a : kArchitectures) names += std::string(names.empty() ? "" : ", ") + a.name;
  return names;
}

void require_kind(const WeightFile& file, ModelKind wanted) {
  const ModelKind kind = model_kind(file);
  if (kind != wanted)
    throw std::runtime_error(file.path() + ": architecture '" + file.get_string("arch") + "' is " +
                             kind_name(kind) + ", not " + kind_name(wanted));
}

}  // namespace

ModelKind model_kind(const WeightFile& file) {
  if (!file.has("arch"))
    throw std::runtime_error(file.path() + ": no 'arch' metadata: not a network weight file");
  const std::string name = file.get_string("arch");
  for (const Architecture& a : kArchitectures)
    if (name == a.name) return a.kind;
  throw std::runtime_error(file.path() + ": unknown architecture '" + name + "' (this build runs " +
                           known_names() + ")");
}

std::string model_name(const WeightFile& file) {
  return model_kind(file) == ModelKind::Depth ? file.get_string("depth.variant") : "inpaint";
}

std::unique_ptr<DepthModel> load_depth_model(const WeightFile& file, const KernelTable& table) {
  require_kind(file, ModelKind::Depth);
  if (file.get_string("arch") == arch::kDepthDinoV2Dpt)
    return std::make_unique<DepthAnythingNet>(DepthAnythingNet::from_file(file, table));
  return std::make_unique<DepthNet>(DepthNet::from_file(file, table));
}

std::unique_ptr<DepthModel> load_depth_model(const std::string& path, const KernelTable& table) {
  return load_depth_model(WeightFile::open(path), table);
}

InpaintNet load_inpaint_net(const std::string& path, const KernelTable& table) {
  const WeightFile file = WeightFile::open(path);
  require_kind(file, ModelKind::Inpaint);
  return InpaintNet::from_file(file, table);
}

}  // namespace ampi
