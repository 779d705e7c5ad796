#pragma once
// All-or-nothing file output: everything is written to a temporary beside the target, which is
// renamed over the target only by commit(). A failure or exception before that leaves no
// half-written file behind (the temporary is removed).

#include <filesystem>
#include <fstream>

namespace vrd {

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ofstream& stream() { return out_; }
  /// Flushes, checks that every write succeeded and moves the file into place; throws vrd::Error.
  void commit();

 private:
  std::filesystem::path target_, temp_;
  std::ofstream out_;
  bool committed_ = false;
};

}  // namespace vrd
