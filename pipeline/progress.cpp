#include "pipeline/progress.h"

#include <cstdio>
#include <cstring>
#include <exception>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace ampi {
namespace {

// A "Name:   123 kB" line of /proc/self/status, in MB; 0 if absent.
double status_mb(const char* name) {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return 0;
  char line[256];
  double mb = 0;
  const size_t n = std::strlen(name);
  while (std::fgets(line, sizeof line, f)) {
    long kb = 0;
    if (std::strncmp(line, name, n) == 0 && line[n] == ':' && std::sscanf(line + n + 1, "%ld", &kb) == 1) {
      mb = kb / 1024.0;
      break;
    }
  }
  std::fclose(f);
  return mb;
}

}  // namespace

double peak_rss_mb() { return status_mb("VmHWM"); }

bool reset_peak_rss() {
  std::FILE* f = std::fopen("/proc/self/clear_refs", "w");
  if (!f) return false;
  const bool ok = std::fputs("5", f) >= 0;
  return std::fclose(f) == 0 && ok;
}

void release_free_memory(size_t at_least) {
#if defined(__GLIBC__) && (__GLIBC__ > 2 || __GLIBC_MINOR__ >= 33)
  if (at_least == 0 || mallinfo2().fordblks >= at_least) malloc_trim(0);
#elif defined(__GLIBC__)
  if (at_least == 0) malloc_trim(0);
#else
  (void)at_least;
#endif
}

void Progress::note(const std::string& text) const {
  if (!quiet_) std::fprintf(stderr, "ampi: %s\n", text.c_str());
}

void Progress::finish(const std::string& name, std::chrono::steady_clock::time_point start) {
  // A stage that throws is not reported as done.
  if (std::uncaught_exceptions() > 0) return;
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  times_.emplace_back(name, ms);
  // Housekeeping between stages, outside the stage's time.
  release_free_memory(size_t(64) << 20);
  if (measure_memory_) peaks_.emplace_back(name, peak_rss_mb());
  if (!quiet_) std::fprintf(stderr, "ampi:   %-12s %8.0f ms\n", name.c_str(), ms);
}

}  // namespace ampi
