#include "engine/thread_pool.h"

#include <algorithm>
#include <chrono>
#include <memory>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace ampi {
namespace {

// Tells the core this is a spin loop (it yields to a sibling hardware thread and saves
// power without giving up the time slice).
inline void cpu_relax() {
#if defined(__x86_64__)
  _mm_pause();
#elif defined(__aarch64__)
  __asm__ __volatile__("yield");
#endif
}

// Set for a pool's workers for life, and for a caller while its loop runs.
thread_local bool t_inside_loop = false;
thread_local int t_worker_index = 0;

}  // namespace

int ThreadPool::thread_index() { return t_worker_index; }

template <class Done>
bool ThreadPool::spin_until(Done done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::microseconds(kSpinMicros);
  for (;;) {
    for (int i = 0; i < 64; ++i) {
      if (done()) return true;
      cpu_relax();
    }
    if (std::chrono::steady_clock::now() >= deadline) return done();
  }
}

ThreadPool::ThreadPool(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads_ = threads;
  for (int i = 1; i < threads_; ++i)
    workers_.emplace_back([this, i] {
      t_inside_loop = true;
      t_worker_index = i;
      worker_loop();
    });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (auto& t : workers_) t.join();
}

void ThreadPool::run_chunks() {
  for (;;) {
    int64_t chunk;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (next_chunk_ >= chunks_ || error_) return;
      chunk = next_chunk_++;
    }
    const int64_t begin = chunk * chunk_;
    const int64_t end = std::min(count_, begin + chunk_);
    try {
      (*body_)(begin, end);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = std::current_exception();
    }
  }
}

void ThreadPool::worker_loop() {
  uint64_t seen = 0;
  for (;;) {
    spin_until([&] { return published_generation_.load(std::memory_order_acquire) != seen; });
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (!stopping_ && generation_ == seen) {
        ++sleeping_workers_;
        wake_.wait(lock, [&] { return stopping_ || generation_ != seen; });
        --sleeping_workers_;
      }
      if (stopping_) return;
      seen = generation_;
      busy_workers_seen_.store(++busy_workers_, std::memory_order_release);
    }
    run_chunks();
    bool wake_caller = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      busy_workers_seen_.store(--busy_workers_, std::memory_order_release);
      wake_caller = caller_sleeping_;
    }
    if (wake_caller) done_.notify_one();
  }
}

void ThreadPool::parallel_for(int64_t count, int64_t grain,
                              const std::function<void(int64_t, int64_t)>& body) {
  if (count <= 0) return;
  grain = std::max<int64_t>(1, grain);
  // A few chunks per thread balances uneven work without much locking.
  const int64_t max_chunks = static_cast<int64_t>(threads_) * 4;
  int64_t chunk = std::max(grain, (count + max_chunks - 1) / max_chunks);
  if (threads_ == 1 || count <= grain || t_inside_loop) {
    body(0, count);
    return;
  }
  bool workers_sleeping = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    body_ = &body;
    count_ = count;
    chunk_ = chunk;
    chunks_ = (count + chunk - 1) / chunk;
    next_chunk_ = 0;
    error_ = nullptr;
    published_generation_.store(++generation_, std::memory_order_release);
    workers_sleeping = sleeping_workers_ > 0;
  }
  if (workers_sleeping) wake_.notify_all();
  t_inside_loop = true;
  run_chunks();
  t_inside_loop = false;
  // Every chunk is now taken (or abandoned after an error); wait for the workers still in
  // one. Workers that wake late find no chunks left and leave at once.
  spin_until([&] { return busy_workers_seen_.load(std::memory_order_acquire) == 0; });
  std::exception_ptr error;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto finished = [&] { return busy_workers_ == 0 && (next_chunk_ >= chunks_ || error_); };
    if (!finished()) {
      caller_sleeping_ = true;
      done_.wait(lock, finished);
      caller_sleeping_ = false;
    }
    chunks_ = 0;
    body_ = nullptr;
    error = error_;
    error_ = nullptr;
  }
  if (error) std::rethrow_exception(error);
}

namespace {
std::unique_ptr<ThreadPool>& pool_slot() {
  static std::unique_ptr<ThreadPool> pool;
  return pool;
}
}  // namespace

ThreadPool& default_pool() {
  auto& slot = pool_slot();
  if (!slot) slot = std::make_unique<ThreadPool>(0);
  return *slot;
}

void set_default_threads(int threads) { pool_slot() = std::make_unique<ThreadPool>(threads); }

}  // namespace ampi
