// OpenCV's parallel loops on ampi's pool (pipeline/opencv_threads.h): every index once,
// thread numbers in range, the pool's size reported, results unchanged.
#include <atomic>
#include <catch2/catch.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "engine/thread_pool.h"
#include "pipeline/opencv_threads.h"

using namespace ampi;

TEST_CASE("OpenCV's parallel_for_ runs on the default pool") {
  cv::Mat photo(480, 640, CV_8UC3);
  cv::randu(photo, 0, 256);
  cv::Mat before_resize, before_edges;
  cv::resize(photo, before_resize, {317, 211}, 0, 0, cv::INTER_AREA);
  cv::Canny(before_resize, before_edges, 20, 50);

  run_opencv_on_default_pool();
  set_default_threads(2);
  CHECK(cv::getNumThreads() == 2);
  std::vector<std::atomic<int>> hits(10007);
  std::atomic<int> bad_thread{0};
  cv::parallel_for_(cv::Range(0, static_cast<int>(hits.size())), [&](const cv::Range& r) {
    const int t = cv::getThreadNum();
    if (t < 0 || t >= 2) ++bad_thread;
    for (int i = r.start; i < r.end; ++i) hits[i]++;
  });
  for (auto& h : hits) REQUIRE(h == 1);
  CHECK(bad_thread == 0);

  cv::Mat after_resize, after_edges;
  cv::resize(photo, after_resize, {317, 211}, 0, 0, cv::INTER_AREA);
  cv::Canny(after_resize, after_edges, 20, 50);
  CHECK(cv::norm(after_resize, before_resize, cv::NORM_INF) == 0);
  CHECK(cv::norm(after_edges, before_edges, cv::NORM_INF) == 0);

  cv::setNumThreads(1);  // resizes the pool, as --threads does
  CHECK(default_pool().size() == 1);
  set_default_threads(0);
}
