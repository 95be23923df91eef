#include "cli/args.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace ampi::cli {

ArgParser::ArgParser(std::string command, std::string usage)
    : command_(std::move(command)), usage_(std::move(usage)) {}

void ArgParser::flag(const std::string& name, bool* target) {
  options_.push_back({name, false, [target](const std::string&) { *target = true; }});
}

void ArgParser::flag(const std::string& name, std::function<void()> apply) {
  options_.push_back({name, false, [apply](const std::string&) { apply(); }});
}

void ArgParser::option(const std::string& name, std::string* target) {
  options_.push_back({name, true, [target](const std::string& v) { *target = v; }});
}

void ArgParser::option(const std::string& name, std::function<void(const std::string&)> parse) {
  options_.push_back({name, true, std::move(parse)});
}

void ArgParser::option(const std::string& name, int* target, int lo, int hi) {
  options_.push_back({name, true, [=](const std::string& v) {
                        char* end = nullptr;
                        errno = 0;
                        const long n = std::strtol(v.c_str(), &end, 10);
                        if (v.empty() || *end || errno || n < lo || n > hi)
                          throw std::runtime_error(name + ": '" + v + "' is not a whole number in " +
                                                   std::to_string(lo) + ".." + std::to_string(hi));
                        *target = static_cast<int>(n);
                      }});
}

void ArgParser::option(const std::string& name, double* target, double lo, double hi) {
  options_.push_back({name, true, [=](const std::string& v) {
                        char* end = nullptr;
                        errno = 0;
                        const double x = std::strtod(v.c_str(), &end);
                        if (v.empty() || *end || errno || !(x >= lo && x <= hi)) {
                          char range[64];
                          std::snprintf(range, sizeof range, "%g..%g", lo, hi);
                          throw std::runtime_error(name + ": '" + v + "' is not a number in " + range);
                        }
                        *target = x;
                      }});
}

bool ArgParser::parse(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::fputs(usage_.c_str(), stdout);
      return false;
    }
  }
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.size() < 2 || arg[0] != '-') {
      if (!positionals_) throw std::runtime_error("unexpected argument '" + arg + "'");
      positionals_->push_back(arg);
      continue;
    }
    const Option* match = nullptr;
    for (const Option& o : options_)
      if (o.name == arg) match = &o;
    if (!match) throw std::runtime_error("unknown option '" + arg + "' (see ampi " + command_ + " --help)");
    if (!match->takes_value) {
      match->apply("");
      continue;
    }
    if (i + 1 >= argc) throw std::runtime_error(arg + " needs a value");
    match->apply(argv[++i]);
  }
  return true;
}

std::vector<int> parse_int_list(const std::string& option, const std::string& text, int lo, int hi,
                                const std::string& what) {
  std::vector<int> values;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    size_t used = 0;
    int value = 0;
    try {
      value = std::stoi(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (item.empty() || used != item.size() || value < lo || value > hi)
      throw std::runtime_error(option + ": '" + item + "' is not " + what + " in " + std::to_string(lo) + ".." +
                               std::to_string(hi));
    values.push_back(value);
    start = comma + 1;
  }
  return values;
}

std::array<double, 3> parse_pose(const std::string& text) {
  std::array<double, 3> v{};
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3 || !std::isfinite(v[0]) ||
      !std::isfinite(v[1]) || !std::isfinite(v[2]))
    throw std::runtime_error("--pose: '" + text + "' is not three numbers TX,TY,TZ");
  return v;
}

}  // namespace ampi::cli
