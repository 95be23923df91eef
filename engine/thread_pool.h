// A fixed set of worker threads that split loops between them. The calling thread works
// too, so a pool of N threads runs N-1 workers; a pool of 1 runs everything inline.
//
// A network calls parallel_for once or twice per layer, often only microseconds apart.
// Sleeping and waking a thread costs a system call each way (more in a virtual machine,
// where the wake-up is an interrupt to another virtual CPU), so a thread that runs out of
// work first spins for kSpinMicros, watching for the next job or for the end of the
// current one, and only then sleeps.
#pragma once
#include <atomic>
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
  // done; the first exception thrown by a body is rethrown here. Called from inside a
  // body (of any pool), it runs body(0, count) on the calling thread: nested loops do not
  // queue behind the loop that is waiting for them.
  void parallel_for(int64_t count, int64_t grain,
                    const std::function<void(int64_t, int64_t)>& body);

  // The calling thread's index among those running a loop: 1..N-1 for a pool's workers,
  // 0 for any other thread (a loop's caller works as thread 0).
  static int thread_index();

 private:
  void worker_loop();
  void run_chunks();
  // Spins until done() is true or kSpinMicros pass; returns done().
  template <class Done>
  static bool spin_until(Done done);

  // How long an idle thread spins before it sleeps.
  static constexpr int kSpinMicros = 200;

  int threads_;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  bool stopping_ = false;
  uint64_t generation_ = 0;  // bumped for every parallel_for, wakes the workers
  // Copies of generation_ and busy_workers_ that spinning threads read without the lock;
  // they take it before acting on what they saw.
  std::atomic<uint64_t> published_generation_{0};
  std::atomic<int> busy_workers_seen_{0};
  int sleeping_workers_ = 0;      // guarded by mutex_
  bool caller_sleeping_ = false;  // guarded by mutex_

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
