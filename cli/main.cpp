// ampi: one program, subcommands. Each subcommand lives in its own cli/cmd_*.cpp and is
// listed here; errors reach the user as one line on stderr and a non-zero exit code.
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>

#include "cli/commands.h"
#include "pipeline/opencv_threads.h"

namespace {

struct Command {
  const char* name;
  int (*run)(int argc, char** argv);
  const char* summary;
};

const Command kCommands[] = {
    {"run", ampi::cli::cmd_run, "photo(s) to 3D photo: depth, MPI, video, viewer"},
    {"info", ampi::cli::cmd_info, "print a weight file's metadata and tensor table"},
    {"bench", ampi::cli::cmd_bench, "kernel, network, renderer and pipeline latency"},
    {"slice", ampi::cli::cmd_slice, "cut a depth map into planes (adaptive or uniform), print JSON"},
    {"depth", ampi::cli::cmd_depth, "estimate a photo's disparity, write a 16-bit PNG"},
    {"render", ampi::cli::cmd_render, "new views of a saved MPI: frame, video, GIF, stereo, viewer"},
    {"eval", ampi::cli::cmd_eval, "reproduce the paper's evaluations on a folder of photos"},
    {"distill", ampi::cli::cmd_distill, "label a folder of photos with a teacher's 10x ensemble"},
};

void print_usage(FILE* out) {
  std::fprintf(out, "usage: ampi COMMAND [ARGS...]   (ampi COMMAND --help for details)\n\ncommands:\n");
  for (const Command& c : kCommands) std::fprintf(out, "  %-8s %s\n", c.name, c.summary);
}

}  // namespace

int main(int argc, char** argv) {
  ampi::run_opencv_on_default_pool();
  if (argc < 2) {
    print_usage(stderr);
    return 2;
  }
  if (!std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") || !std::strcmp(argv[1], "help")) {
    print_usage(stdout);
    return 0;
  }
  for (const Command& c : kCommands) {
    if (std::strcmp(argv[1], c.name) != 0) continue;
    try {
      return c.run(argc - 1, argv + 1);
    } catch (const std::bad_alloc&) {
      // What got past the memory-budget checks (engine/memory_budget.h) before allocating.
      std::fprintf(stderr, "ampi %s: out of memory (less was free than the memory budget, AMPI_MEMORY_BUDGET, allowed)\n",
                   c.name);
      return 1;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "ampi %s: %s\n", c.name, e.what());
      return 1;
    }
  }
  std::fprintf(stderr, "ampi: unknown command '%s' (try ampi --help)\n", argv[1]);
  return 2;
}
