// Outputs appear all at once or not at all. A run writes into a hidden staging folder
// beside the destination and, only when every stage succeeded, moves its files into
// place. A failed or interrupted run leaves no partial output under a final name, and
// nothing the user had is touched: an existing destination is refused unless `force`,
// and even then only the entries this run writes are replaced.
#pragma once
#include <string>
#include <vector>

namespace ampi {

class OutputStaging {
 public:
  // Throws std::runtime_error "DEST: problem" when the destination exists and `force`
  // is false, exists as a non-folder, or its parent folder cannot be written.
  OutputStaging(const std::string& destination, bool force);
  ~OutputStaging();  // removes the staging folder unless committed
  OutputStaging(const OutputStaging&) = delete;
  OutputStaging& operator=(const OutputStaging&) = delete;

  // Where to write: a folder on the same file system as the destination.
  const std::string& dir() const { return staging_; }
  const std::string& destination() const { return destination_; }

  // Moves every entry of the staging folder to the destination, replacing entries of
  // the same names. After this the staging folder is gone.
  void commit();

 private:
  std::string destination_;
  std::string staging_;
  bool committed_ = false;
};

}  // namespace ampi
