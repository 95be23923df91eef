// OpenCV's parallel loops (resize, Canny, dilate, warpPerspective, ...) on ampi's default
// thread pool instead of OpenCV's own threads (TBB in Debian's build). Two pools on two
// cores compete: right after the depth network, while the pool's worker still spins for
// its next job, one cv::Canny on a 256x192 map took 362 us waiting for TBB's threads,
// against 40 us when OpenCV runs alone. On one pool, OpenCV's loops follow --threads too.
#pragma once

namespace ampi {

// Installs the pool as OpenCV's parallel_for backend. Call once, early in main(), before
// other threads exist (cv::parallel::setParallelForBackend is not thread-safe).
void run_opencv_on_default_pool();

}  // namespace ampi
