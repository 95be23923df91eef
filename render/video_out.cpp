#include "render/video_out.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

extern char** environ;

namespace ampi {
namespace fs = std::filesystem;
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw std::runtime_error(path + ": " + problem);
}

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// "out/dir/" and "out/dir" name the same destination.
std::string without_trailing_slashes(std::string path) {
  while (path.size() > 1 && path.back() == '/') path.pop_back();
  return path;
}

// A hidden name beside the destination, unique to this process, so the final rename
// stays within one file system. Videos keep their extension: it selects the format.
std::string staging_name(const std::string& path, Container c) {
  const fs::path p(path);
  std::string name = "." + p.filename().string() + ".partial-" + std::to_string(::getpid());
  if (c == Container::Mp4) name += ".mp4";
  if (c == Container::Png) name += ".png";
  return (p.parent_path() / name).string();
}

// Moves `staging` to `dest`; a previous `dest` is set aside first and deleted only after
// the new one is in place (rename cannot replace a directory).
void move_into_place(const std::string& staging, const std::string& dest) {
  const fs::path d(dest);
  fs::path aside;
  if (fs::symlink_status(d).type() != fs::file_type::not_found) {
    aside = d.parent_path() / ("." + d.filename().string() + ".replaced-" + std::to_string(::getpid()));
    fs::rename(d, aside);
  }
  std::error_code error;
  fs::rename(staging, d, error);
  if (error) {
    if (!aside.empty()) fs::rename(aside, d, error);
    fail(dest, "cannot move the finished output into place");
  }
  if (!aside.empty()) fs::remove_all(aside, error);
}

std::vector<char*> argv_of(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  return argv;
}

// The exit status of a finished child (-1 if it did not exit by itself).
int wait_for(pid_t pid) {
  int status = 0;
  pid_t waited;
  do waited = ::waitpid(pid, &status, 0);
  while (waited < 0 && errno == EINTR);
  if (waited < 0) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Whether the child has exited (it stays a zombie until wait_for reaps it).
bool has_exited(pid_t pid) {
  siginfo_t info{};
  const int result = ::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT);
  return result != 0 || info.si_pid == pid;  // an error: nothing left to wait for
}

// A running process's peak resident memory in MB (VmHWM), 0 where /proc cannot tell.
// Not the rusage of the reaped child: a child started by vfork and exec inherits its
// parent's peak there (Linux keeps the replaced memory map's high-water mark).
double peak_resident_mb(pid_t pid) {
  std::FILE* f = std::fopen(("/proc/" + std::to_string(pid) + "/status").c_str(), "r");
  if (!f) return 0;
  char line[256];
  long kb = 0;
  while (std::fgets(line, sizeof line, f))
    if (std::sscanf(line, "VmHWM: %ld", &kb) == 1) break;
  std::fclose(f);
  return kb / 1024.0;
}

int run_program(const std::vector<std::string>& args) {
  std::vector<char*> argv = argv_of(args);
  pid_t pid;
  if (posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0) return -1;
  return wait_for(pid);
}

// Starts `args` with its stdin reading from a new pipe (its write end into *input) and
// its stdout and stderr on /dev/null. Returns the child's pid, or -1.
pid_t spawn_with_input_pipe(const std::vector<std::string>& args, int* input) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) return -1;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  std::vector<char*> argv = argv_of(args);
  pid_t pid;
  const int failed = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[0]);
  if (failed) {
    ::close(fds[1]);
    return -1;
  }
  *input = fds[1];
  return pid;
}

// Whether the ffmpeg program on PATH can encode with libx264 (Debian's can; a minimal
// build may not): one tiny frame encoded to nowhere, tried once per process.
bool ffmpeg_encodes_h264() {
  if (!program_on_path("ffmpeg")) return false;
  static const bool encodes = [] {
    int input = -1;
    const pid_t pid = spawn_with_input_pipe(
        {"ffmpeg", "-nostdin", "-v", "error", "-f", "lavfi", "-i", "color=s=16x16:d=0.04", "-c:v", "libx264",
         "-f", "null", "-"},
        &input);
    if (pid < 0) return false;
    ::close(input);
    return wait_for(pid) == 0;
  }();
  return encodes;
}

// Writes all of [data, data + size) to fd; false if the reader went away.
bool write_all(int fd, const uint8_t* data, size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    size -= static_cast<size_t>(n);
  }
  return true;
}

}  // namespace

Container container_for_path(const std::string& path) {
  const std::string ext = lower_extension(without_trailing_slashes(path));
  if (ext == ".mp4") return Container::Mp4;
  if (ext == ".gif") return Container::Gif;
  if (ext == ".png") return Container::Png;
  return Container::PngSequence;
}

const char* container_name(Container c) {
  switch (c) {
    case Container::Mp4: return "mp4";
    case Container::Gif: return "gif";
    case Container::PngSequence: return "png sequence";
    case Container::Png: return "png";
  }
  return "?";
}

bool program_on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::string dirs = path;
  size_t start = 0;
  while (start <= dirs.size()) {
    const size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::string dir = dirs.substr(start, end - start);
    const std::string candidate = (dir.empty() ? "." : dir) + "/" + name;
    if (::access(candidate.c_str(), X_OK) == 0 && fs::is_regular_file(candidate)) return true;
    start = end + 1;
  }
  return false;
}

FrameWriter::FrameWriter(const std::string& path, Container container, double fps, bool overwrite)
    : path_(without_trailing_slashes(path)), container_(container), fps_(fps), overwrite_(overwrite) {
  if (path_.empty()) throw std::runtime_error("the output path is empty");
  if (!(fps > 0)) fail(path_, "fps must be positive");
  if (!overwrite && fs::symlink_status(path_).type() != fs::file_type::not_found)
    fail(path_, "already exists (use --force to replace it)");
  const fs::path parent = fs::path(path_).parent_path();
  if (!parent.empty() && !fs::is_directory(parent)) fail(path_, "directory " + parent.string() + " does not exist");
  if (container == Container::Gif && !program_on_path("ffmpeg"))
    fail(path_, "GIF output needs the ffmpeg program, which is not on PATH (install ffmpeg, or write .mp4 or PNG frames)");
  staging_ = staging_name(path_, container);
  std::error_code ignored;
  fs::remove_all(staging_, ignored);  // left by an earlier process with our pid
  if (container == Container::PngSequence || container == Container::Gif) fs::create_directory(staging_);
}

FrameWriter::~FrameWriter() {
  if (finished_) return;
  stop_encoder();
  video_.release();
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
  fs::remove(staging_ + ".gif", ignored);
}

const char* const kMp4EncoderSettings = "rc-lookahead=10:sync-lookahead=0:threads=2";

void FrameWriter::start_encoder(cv::Size size) {
  // A reader that dies would otherwise kill this process with SIGPIPE on the next write;
  // ignored, the write fails with EPIPE and the error names the video.
  ::signal(SIGPIPE, SIG_IGN);
  char fps[32];
  std::snprintf(fps, sizeof fps, "%.6g", fps_);
  encoder_pid_ = spawn_with_input_pipe(
      {"ffmpeg", "-nostdin", "-v", "error", "-y", "-f", "rawvideo", "-pix_fmt", "bgr24", "-s",
       std::to_string(size.width) + "x" + std::to_string(size.height), "-framerate", fps, "-i", "pipe:0",
       "-an", "-c:v", "libx264", "-preset", "medium", "-crf", "23", "-pix_fmt", "yuv420p", "-x264-params",
       kMp4EncoderSettings, "-f", "mp4", staging_},
      &encoder_input_);
  if (encoder_pid_ < 0) fail(path_, "cannot start the ffmpeg program to encode the video");
}

void FrameWriter::send_to_encoder(const cv::Mat& bgr) {
  bool sent = true;
  if (bgr.isContinuous())
    sent = write_all(encoder_input_, bgr.data, bgr.total() * bgr.elemSize());
  else
    for (int y = 0; y < bgr.rows && sent; ++y)
      sent = write_all(encoder_input_, bgr.ptr<uint8_t>(y), bgr.cols * bgr.elemSize());
  if (!sent) fail(path_, "the ffmpeg program stopped while encoding the video");
  // x264 holds its most frames once its lookahead is full; flushing at the end adds none.
  encoder_peak_mb_ = std::max(encoder_peak_mb_, peak_resident_mb(encoder_pid_));
}

void FrameWriter::finish_encoder() {
  if (encoder_pid_ < 0) return;
  ::close(encoder_input_);  // end of input: ffmpeg flushes x264 and writes the MP4's index
  encoder_input_ = -1;
  // Frames sit in the pipe and in x264's lookahead when the last one is handed over, so
  // the peak is followed until the encoder exits.
  while (!has_exited(encoder_pid_)) {
    encoder_peak_mb_ = std::max(encoder_peak_mb_, peak_resident_mb(encoder_pid_));
    ::usleep(5000);
  }
  const int status = wait_for(encoder_pid_);
  encoder_pid_ = -1;
  if (status != 0) fail(path_, "ffmpeg could not encode the video (exit status " + std::to_string(status) + ")");
}

// A writer given up on: the encoder is stopped rather than left to finish a file that
// will be deleted.
void FrameWriter::stop_encoder() {
  if (encoder_pid_ < 0) return;
  ::close(encoder_input_);
  ::kill(encoder_pid_, SIGTERM);
  wait_for(encoder_pid_);
  encoder_pid_ = -1;
  encoder_input_ = -1;
}

void FrameWriter::open_video(cv::Size size) {
  if (ffmpeg_encodes_h264()) return start_encoder(size);
  // The FFmpeg backend logs its own complaint when a codec is missing; we report ours.
  const auto level = cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  video_.open(staging_, cv::VideoWriter::fourcc('a', 'v', 'c', '1'), fps_, size);
  if (!video_.isOpened()) {
    video_.open(staging_, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), fps_, size);
    note_ = "no H.264 encoder in this OpenCV build: wrote MPEG-4 Part 2 video instead";
  }
  cv::utils::logging::setLogLevel(level);
  if (!video_.isOpened()) fail(path_, "OpenCV cannot write MP4 video here (no FFmpeg or GStreamer backend?)");
}

void FrameWriter::write_png(const std::string& file, const cv::Mat& bgr) const {
  bool written = false;
  try {
    written = cv::imwrite(file, bgr);
  } catch (const cv::Exception&) {
    written = false;
  }
  if (!written) fail(path_, "cannot write PNG image " + file);
}

void FrameWriter::add(const cv::Mat& bgr) {
  if (finished_) throw std::logic_error("FrameWriter::add after finish");
  if (bgr.type() != CV_8UC3 || bgr.empty()) throw std::invalid_argument("FrameWriter::add needs a CV_8UC3 frame");
  if (frames_ == 0) size_ = bgr.size();
  if (bgr.size() != size_) throw std::invalid_argument("FrameWriter::add: the frame size changed");
  if (container_ == Container::Png && frames_ == 1) fail(path_, "a .png output holds a single frame");
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06d.png", frames_);
  switch (container_) {
    case Container::Mp4: {
      cv::Mat even = bgr;
      if (bgr.cols % 2 || bgr.rows % 2)
        cv::copyMakeBorder(bgr, even, 0, bgr.rows % 2, 0, bgr.cols % 2, cv::BORDER_REPLICATE);
      if (frames_ == 0) open_video(even.size());
      if (encoder_pid_ >= 0)
        send_to_encoder(even);
      else
        video_.write(even);
      break;
    }
    case Container::Gif:
    case Container::PngSequence: write_png((fs::path(staging_) / name).string(), bgr); break;
    case Container::Png: write_png(staging_, bgr); break;
  }
  ++frames_;
}

// Two passes in one filter graph: palettegen finds the 256 colours that suit the whole
// clip, paletteuse maps every frame onto them.
void FrameWriter::encode_gif() const {
  const int status = run_program(
      {"ffmpeg", "-v", "error", "-nostdin", "-y", "-framerate", std::to_string(fps_), "-i",
       (fs::path(staging_) / "frame_%06d.png").string(), "-filter_complex",
       "split[frames][copy];[copy]palettegen[palette];[frames][palette]paletteuse", "-loop", "0",
       staging_ + ".gif"});
  if (status != 0) fail(path_, "ffmpeg could not make the GIF (exit status " + std::to_string(status) + ")");
}

void FrameWriter::finish() {
  if (finished_) return;
  if (frames_ == 0) fail(path_, "no frames were rendered");
  if (!overwrite_ && fs::symlink_status(path_).type() != fs::file_type::not_found)
    fail(path_, "appeared while rendering; not replaced (use --force to replace it)");
  video_.release();
  finish_encoder();
  if (container_ == Container::Gif) {
    encode_gif();
    move_into_place(staging_ + ".gif", path_);
    std::error_code ignored;
    fs::remove_all(staging_, ignored);
  } else {
    move_into_place(staging_, path_);
  }
  finished_ = true;
}

StereoPoses stereo_poses(const Pose& centre, double baseline) {
  // Moving the camera by d in its own frame: X_eye = X_new - d, so t_eye = t - d.
  StereoPoses eyes{centre, centre};
  eyes.left.t[0] += 0.5 * baseline;
  eyes.right.t[0] -= 0.5 * baseline;
  return eyes;
}

cv::Mat side_by_side(const cv::Mat& left, const cv::Mat& right) {
  cv::Mat out;
  cv::hconcat(left, right, out);
  return out;
}

cv::Mat anaglyph(const cv::Mat& left, const cv::Mat& right) {
  CV_Assert(left.size() == right.size() && left.type() == CV_8UC3 && right.type() == CV_8UC3);
  cv::Mat out(left.size(), CV_8UC3);
  const cv::Mat sources[] = {left, right};
  // BGR: blue and green (cyan) from the right eye, red from the left.
  const int from_to[] = {3, 0, 4, 1, 2, 2};
  cv::mixChannels(sources, 2, &out, 1, from_to, 3);
  return out;
}

}  // namespace ampi
