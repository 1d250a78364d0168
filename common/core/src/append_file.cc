#include "tamp/core/append_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <utility>

namespace tamp {
namespace {

Error ioError(const std::filesystem::path& path, const std::string& what) {
  return Error(ErrorCode::kIo, what + ": " + std::strerror(errno), SourceLocation{path.string()});
}

}  // namespace

bool writeAll(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

Status syncDirectory(const std::filesystem::path& dir, const std::string& what) {
  const int d = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (d < 0) return ioError(dir, "cannot open the folder of " + what);
  const bool synced = ::fsync(d) == 0;
  ::close(d);
  if (!synced) return ioError(dir, "cannot sync the folder of " + what);
  return Status::Ok();
}

Result<std::string> readFileIfExists(const std::filesystem::path& file, const std::string& what) {
  if (!std::filesystem::exists(file)) return std::string();
  std::ifstream in(file, std::ios::binary);
  if (!in) return ioError(file, "cannot read " + what);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

Result<AppendFile> AppendFile::open(const std::filesystem::path& file, const std::string& what) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) return ioError(file, "cannot open " + what + " for appending");
  return AppendFile(file, what, fd);
}

AppendFile::AppendFile(std::filesystem::path path, std::string what, int fd)
    : path_(std::move(path)), what_(std::move(what)), fd_(fd) {}

AppendFile::AppendFile(AppendFile&& o) noexcept
    : path_(std::move(o.path_)), what_(std::move(o.what_)), fd_(std::exchange(o.fd_, -1)) {}

AppendFile& AppendFile::operator=(AppendFile&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(o.path_);
    what_ = std::move(o.what_);
    fd_ = std::exchange(o.fd_, -1);
  }
  return *this;
}

AppendFile::~AppendFile() {
  if (fd_ >= 0) ::close(fd_);
}

Status AppendFile::append(const std::string& text, bool sync) {
  if (fd_ < 0) return Status::Ok();
  if (!writeAll(fd_, text)) return ioError(path_, "cannot append to " + what_);
  if (sync && ::fdatasync(fd_) != 0) return ioError(path_, "cannot sync " + what_);
  return Status::Ok();
}

Status AppendFile::truncate(std::size_t size) {
  if (::ftruncate(fd_, static_cast<off_t>(size)) != 0) {
    return ioError(path_, "cannot cut the torn last line off " + what_);
  }
  return Status::Ok();
}

}  // namespace tamp
