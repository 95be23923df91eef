#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>

#include "pipeline/output_staging.h"

namespace fs = std::filesystem;
using namespace ampi;

namespace {

// A path that does not exist yet, alone in a folder of its own.
fs::path fresh_dir(const char* name) {
  fs::path dir = fs::temp_directory_path() / ("ampi_staging_" + std::to_string(::getpid())) / name / "out";
  fs::remove_all(dir);
  fs::create_directories(dir.parent_path());
  return dir;
}

void write_text(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

TEST_CASE("a committed staging folder appears at the destination, nothing is left beside it") {
  const fs::path dest = fresh_dir("new");
  {
    OutputStaging staging(dest.string(), false);
    write_text(fs::path(staging.dir()) / "depth.png", "d");
    fs::create_directories(fs::path(staging.dir()) / "mpi");
    write_text(fs::path(staging.dir()) / "mpi" / "mpi.json", "{}");
    CHECK_FALSE(fs::exists(dest));  // nothing under the final name before commit
    staging.commit();
  }
  CHECK(read_text(dest / "depth.png") == "d");
  CHECK(read_text(dest / "mpi" / "mpi.json") == "{}");
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dest.parent_path())) entries += e.path() != dest;
  CHECK(entries == 0);
}

TEST_CASE("an abandoned staging folder leaves no trace") {
  const fs::path dest = fresh_dir("abandoned");
  {
    OutputStaging staging(dest.string(), false);
    write_text(fs::path(staging.dir()) / "video.mp4", "half");
  }
  CHECK_FALSE(fs::exists(dest));
  CHECK(fs::is_empty(dest.parent_path()));
}

TEST_CASE("an existing destination is refused without force; with force only ampi's entries change") {
  const fs::path dest = fresh_dir("existing");
  fs::create_directories(dest);
  write_text(dest / "notes.txt", "mine");
  write_text(dest / "depth.png", "old");
  CHECK_THROWS_WITH(OutputStaging(dest.string(), false),
                    Catch::Contains("already exists; pass --force"));
  {
    OutputStaging staging(dest.string(), true);
    write_text(fs::path(staging.dir()) / "depth.png", "new");
    staging.commit();
  }
  CHECK(read_text(dest / "notes.txt") == "mine");
  CHECK(read_text(dest / "depth.png") == "new");
  const fs::path file = fresh_dir("afile");
  write_text(file, "x");
  CHECK_THROWS_WITH(OutputStaging(file.string(), true), Catch::Contains("not a folder"));
  fs::remove_all(dest.parent_path());
}
