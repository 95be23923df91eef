// A small declarative command-line parser for the subcommands: options bind straight to
// fields, numbers are range-checked, and every mistake is one line naming the option.
#pragma once
#include <array>
#include <functional>
#include <string>
#include <vector>

namespace ampi::cli {

class ArgParser {
 public:
  // usage: the full --help text.
  ArgParser(std::string command, std::string usage);

  void flag(const std::string& name, bool* target);
  void flag(const std::string& name, std::function<void()> apply);
  void option(const std::string& name, std::string* target);
  void option(const std::string& name, int* target, int lo, int hi);
  void option(const std::string& name, double* target, double lo, double hi);
  // Any option with a custom conversion of its value (throws std::runtime_error).
  void option(const std::string& name, std::function<void(const std::string&)> parse);
  // Arguments that are not options, in order.
  void positionals(std::vector<std::string>* target) { positionals_ = target; }

  // Returns false when --help was asked for (the usage is printed to stdout); throws
  // std::runtime_error for an unknown option, a missing or bad value.
  bool parse(int argc, char** argv);

 private:
  struct Option {
    std::string name;
    bool takes_value;
    std::function<void(const std::string&)> apply;
  };
  std::string command_, usage_;
  std::vector<Option> options_;
  std::vector<std::string>* positionals_ = nullptr;
};

// A comma-separated list of integers in [lo, hi]; throws std::runtime_error
// "OPTION: 'ITEM' is not WHAT in LO..HI" for the first bad item.
std::vector<int> parse_int_list(const std::string& option, const std::string& text, int lo, int hi,
                                const std::string& what);

// --pose's value: three finite numbers TX,TY,TZ; throws std::runtime_error otherwise.
std::array<double, 3> parse_pose(const std::string& text);

}  // namespace ampi::cli
