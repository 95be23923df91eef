// OpenCV's parallel loops (resize, Canny, dilate, warpPerspective, ...) on ampi's default
// thread pool instead of OpenCV's own threads (TBB in Debian's build). Two pools on two
// cores compete: right after the depth network, while the pool's worker still spins for
// its next job, OpenCV's calls waited for TBB's threads several times longer than they
// take alone. On one pool, OpenCV's loops follow --threads too.
#pragma once

namespace ampi {

// Installs the pool as OpenCV's parallel_for backend. Call once, early in main(), before
// other threads exist (cv::parallel::setParallelForBackend is not thread-safe).
void run_opencv_on_default_pool();

}  // namespace ampi
