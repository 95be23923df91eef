// The bundled weight files: where they are and which is which, for every command that
// runs a network without --weights.
//
// The folder is the one named by the environment variable AMPI_WEIGHTS_DIR (when set, the
// only place looked), else weights/ beside the executable or one level above it (a build
// folder inside the source tree: build/ampi finds ../weights/), else share/ampi/weights/
// one level above it (an installed /usr/bin/ampi finds /usr/share/ampi/weights/). Files
// are told apart by their metadata, never by their names: a depth model is the
// depth-network file whose model name (nets/model_loader.h, model_name) is the one asked
// for.
#pragma once
#include <string>
#include <vector>

namespace ampi {

// The bundled depth models' names ("heavy", "lite", ...), sorted.
std::vector<std::string> bundled_depth_models();

// Throws std::runtime_error "--model: 'NAME' is not a bundled depth model (bundled: ...)"
// unless `model` names one: what a command checks before it starts any work.
void check_depth_model_name(const std::string& model);

// `weights` when not empty (the user's --weights), else the bundled depth model `model`.
// Throws std::runtime_error naming the model, the folders searched and the models they
// hold when none matches.
std::string depth_weights_path(const std::string& weights, const std::string& model);

// `weights` when not empty, else the bundled inpainting network.
std::string inpaint_weights_path(const std::string& weights = {});

}  // namespace ampi
