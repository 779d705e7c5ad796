#include "vrdeform/core/atomic_file.h"

#include <fmt/format.h>
#include <unistd.h>

#include <system_error>

#include "vrdeform/core/write_file.h"
#include "vrdeform/error.h"

namespace vrd {

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  temp_ = target_;
  temp_ += fmt::format(".tmp{}", ::getpid());
  out_.open(temp_, std::ios::binary | std::ios::trunc);
  if (!out_) throw Error(fmt::format("cannot write {}: cannot create {}", target_.string(), temp_.string()));
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  out_.close();
  std::error_code ignored;
  std::filesystem::remove(temp_, ignored);
}

void AtomicFile::commit() {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok) throw Error(fmt::format("cannot write {}: write failed (disk full?)", target_.string()));
  std::error_code error;
  std::filesystem::rename(temp_, target_, error);
  if (error) throw Error(fmt::format("cannot write {}: {}", target_.string(), error.message()));
  committed_ = true;
}

void writeFile(const std::filesystem::path& path, std::string_view text) {
  AtomicFile file(path);
  file.stream().write(text.data(), std::streamsize(text.size()));
  file.commit();
}

void prepareOutputFolder(const std::filesystem::path& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw Error(fmt::format("{}: cannot make the output folder: {}", dir.string(), error.message()));
  if (!std::filesystem::is_directory(dir, error))
    throw Error(fmt::format("{}: the output folder is a file", dir.string()));
  const std::filesystem::path probe = dir / fmt::format(".vrdeform-probe{}", ::getpid());
  const bool writable = std::ofstream(probe, std::ios::binary).good();
  std::filesystem::remove(probe, error);
  if (!writable) throw Error(fmt::format("{}: cannot write in the output folder", dir.string()));
}

}  // namespace vrd
