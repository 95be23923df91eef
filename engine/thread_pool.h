// A fixed set of worker threads that split loops between them. The calling thread works
// too, so a pool of N threads runs N-1 workers; a pool of 1 runs everything inline.
#pragma once
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace ampi {

class ThreadPool {
 public:
  // threads <= 0 means one per hardware thread.
  explicit ThreadPool(int threads = 0);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int size() const { return threads_; }

  // Calls body(begin, end) on disjoint sub-ranges covering [0, count), each at least
  // `grain` long (except the last), spread over the pool's threads. Returns when all are
  // done; the first exception thrown by a body is rethrown here.
  void parallel_for(int64_t count, int64_t grain,
                    const std::function<void(int64_t, int64_t)>& body);

 private:
  void worker_loop();
  void run_chunks();

  int threads_;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  bool stopping_ = false;
  uint64_t generation_ = 0;  // bumped for every parallel_for, wakes the workers

  // The job in flight (guarded by the generation handshake).
  const std::function<void(int64_t, int64_t)>* body_ = nullptr;
  int64_t count_ = 0, chunk_ = 0, chunks_ = 0;
  int64_t next_chunk_ = 0;   // guarded by mutex_
  int busy_workers_ = 0;     // guarded by mutex_
  std::exception_ptr error_;
};

// The process-wide pool the pipeline uses; created on first use with
// set_default_threads()'s count (default: hardware threads).
ThreadPool& default_pool();
// Replaces the default pool; call before work starts (e.g. from --threads).
void set_default_threads(int threads);

}  // namespace ampi
