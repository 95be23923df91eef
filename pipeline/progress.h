// Per-stage progress on stderr ("ampi: depth        412 ms") and the stage times kept
// for benchmarks.
#pragma once
#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace ampi {

class Progress {
 public:
  explicit Progress(bool quiet = false) : quiet_(quiet) {}

  // Runs body() as the stage `name`, timing it.
  template <class Body>
  auto stage(const std::string& name, Body&& body) -> decltype(body()) {
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
  void clear() { times_.clear(); }

 private:
  void finish(const std::string& name, std::chrono::steady_clock::time_point start);

  bool quiet_;
  std::vector<std::pair<std::string, double>> times_;
};

}  // namespace ampi
