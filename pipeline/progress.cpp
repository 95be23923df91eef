#include "pipeline/progress.h"

#include <cstdio>
#include <exception>

namespace ampi {

void Progress::note(const std::string& text) const {
  if (!quiet_) std::fprintf(stderr, "ampi: %s\n", text.c_str());
}

void Progress::finish(const std::string& name, std::chrono::steady_clock::time_point start) {
  // A stage that throws is not reported as done.
  if (std::uncaught_exceptions() > 0) return;
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  times_.emplace_back(name, ms);
  if (!quiet_) std::fprintf(stderr, "ampi:   %-12s %8.0f ms\n", name.c_str(), ms);
}

}  // namespace ampi
