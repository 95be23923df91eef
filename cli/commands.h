// The subcommands of the ampi program. Each takes its own argv (argv[0] is the
// subcommand's name), returns the exit code, and may throw: main prints the message.
#pragma once

namespace ampi::cli {

int cmd_run(int argc, char** argv);
int cmd_info(int argc, char** argv);
int cmd_bench(int argc, char** argv);
int cmd_slice(int argc, char** argv);
int cmd_depth(int argc, char** argv);
int cmd_render(int argc, char** argv);
int cmd_eval(int argc, char** argv);
int cmd_distill(int argc, char** argv);

}  // namespace ampi::cli
