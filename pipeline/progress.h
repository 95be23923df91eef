// Per-stage progress on stderr ("ampi: depth        412 ms") and the stage times kept
// for benchmarks; on request, each stage's peak resident memory where the system can
// tell it (`ampi bench pipeline` shows it per stage).
#pragma once
#include <chrono>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace ampi {

// The process's peak resident memory in MB since the last reset_peak_rss() (or since it
// started); 0 where /proc cannot tell.
double peak_rss_mb();
// Starts a new peak window (Linux: /proc/self/clear_refs); false where unsupported,
// and the peak then stays the one since the process started. The reset also lowers
// what getrusage and `/usr/bin/time -v` report as the process's maximum, so only
// measuring code calls it.
bool reset_peak_rss();
// Hands the heap's free pages back to the system (glibc: malloc_trim) when it holds at
// least `at_least` bytes free. Buffers under malloc's mmap threshold (it grows up to
// 32 MB) are freed into the heap and kept there, and the next stage's larger buffers
// would come on top of them. Progress does it after every stage that leaves 64 MB or
// more free (smaller amounts are kept: giving them back would cost the next stage page
// faults), `ampi run` after every photo.
void release_free_memory(size_t at_least = 0);

class Progress {
 public:
  // measure_memory: record each stage's peak resident memory (peaks_mb()); it resets
  // the process's peak at every stage (reset_peak_rss), so `ampi run` leaves it off.
  explicit Progress(bool quiet = false, bool measure_memory = false)
      : quiet_(quiet), measure_memory_(measure_memory) {}

  // Runs body() as the stage `name`, timing it (and measuring its peak memory).
  template <class Body>
  auto stage(const std::string& name, Body&& body) -> decltype(body()) {
    if (measure_memory_) reset_peak_rss();
    const auto start = std::chrono::steady_clock::now();
    struct Finish {  // records the time even when body() returns a value
      Progress* self;
      const std::string& name;
      std::chrono::steady_clock::time_point start;
      ~Finish() { self->finish(name, start); }
    } finish{this, name, start};
    return body();
  }

  // A line of its own (e.g. which photo starts), unless quiet.
  void note(const std::string& text) const;

  const std::vector<std::pair<std::string, double>>& times_ms() const { return times_; }
  // Per stage, the process's peak resident memory (MB) while it ran; empty unless
  // measure_memory.
  const std::vector<std::pair<std::string, double>>& peaks_mb() const { return peaks_; }
  void clear() {
    times_.clear();
    peaks_.clear();
  }

 private:
  void finish(const std::string& name, std::chrono::steady_clock::time_point start);

  bool quiet_;
  bool measure_memory_;
  std::vector<std::pair<std::string, double>> times_;
  std::vector<std::pair<std::string, double>> peaks_;
};

}  // namespace ampi
