// Where the bundled weight files are found when the user names none.
#pragma once
#include <string>

namespace ampi {

// The path of the bundled weight file `file_name` (e.g. "depth_lite.ampw"), searched in
// order: the folder named by the environment variable AMPI_WEIGHTS_DIR (when set, the
// only place looked), then weights/ beside the executable and one level above it (a
// build folder inside the source tree: build/ampi finds ../weights/). Throws
// std::runtime_error naming the file and the folders searched when none holds it.
std::string find_weights(const std::string& file_name);

}  // namespace ampi
