#include "pipeline/opencv_threads.h"

#include <algorithm>
#include <memory>
#include <opencv2/core/parallel/parallel_backend.hpp>

#include "engine/thread_pool.h"

namespace ampi {
namespace {

class DefaultPoolBackend : public cv::parallel::ParallelForAPI {
 public:
  void parallel_for(int tasks, FN_parallel_for_body_cb_t body, void* data) override {
    default_pool().parallel_for(tasks, 1, [&](int64_t begin, int64_t end) {
      body(static_cast<int>(begin), static_cast<int>(end), data);
    });
  }
  int getThreadNum() const override { return ThreadPool::thread_index(); }
  int getNumThreads() const override { return default_pool().size(); }
  // cv::setNumThreads resizes the pool, as --threads does (no loop is running then).
  // OpenCV's 0 means no threads, a negative count its default: one per core.
  int setNumThreads(int threads) override {
    const int previous = default_pool().size();
    set_default_threads(threads == 0 ? 1 : std::max(threads, 0));
    return previous;
  }
  const char* getName() const override { return "ampi"; }
};

}  // namespace

void run_opencv_on_default_pool() {
  cv::parallel::setParallelForBackend(std::make_shared<DefaultPoolBackend>(), /*propagateNumThreads=*/false);
}

}  // namespace ampi
