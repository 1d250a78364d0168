#include "tamp/execution_monitor/sent_journal.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace tamp::execution_monitor {

namespace {

Error ioError(const std::filesystem::path& path, const std::string& what) {
  return Error(ErrorCode::kIo, what + ": " + std::strerror(errno), SourceLocation{path.string()});
}

/// The complete lines of `text` (a last line without its newline was torn by a crash).
std::vector<std::string> completeLines(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (std::size_t nl = text.find('\n'); nl != std::string::npos; nl = text.find('\n', start)) {
    if (nl > start) out.push_back(text.substr(start, nl - start));
    start = nl + 1;
  }
  return out;
}

void syncDirectory(const std::filesystem::path& dir) {
  const int d = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (d < 0) return;
  (void)::fsync(d);
  ::close(d);
}

}  // namespace

Result<SentJournal> SentJournal::open(const std::filesystem::path& path) {
  std::vector<std::string> previous;
  if (std::filesystem::exists(path)) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return ioError(path, "cannot read the execution monitor's journal");
    std::ostringstream text;
    text << in.rdbuf();
    previous = completeLines(text.str());
  }
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) return ioError(path, "cannot open the execution monitor's journal for appending");
  // A torn last line is cut off so that the next id starts on a line of its own.
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > 0) {
    std::ifstream in(path, std::ios::binary);
    in.seekg(static_cast<std::streamoff>(size) - 1);
    if (in.get() != '\n' && ::write(fd, "\n", 1) != 1) {
      ::close(fd);
      return ioError(path, "cannot repair the execution monitor's journal");
    }
  }
  syncDirectory(path.parent_path());
  return SentJournal(path, fd, std::move(previous));
}

SentJournal::SentJournal(std::filesystem::path path, int fd, std::vector<std::string> previous)
    : path_(std::move(path)), fd_(fd), previous_(std::move(previous)) {
  ids_.insert(previous_.begin(), previous_.end());
}

SentJournal::SentJournal(SentJournal&& o) noexcept
    : path_(std::move(o.path_)),
      fd_(std::exchange(o.fd_, -1)),
      previous_(std::move(o.previous_)),
      ids_(std::move(o.ids_)) {}

SentJournal& SentJournal::operator=(SentJournal&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(o.path_);
    fd_ = std::exchange(o.fd_, -1);
    previous_ = std::move(o.previous_);
    ids_ = std::move(o.ids_);
  }
  return *this;
}

SentJournal::~SentJournal() {
  if (fd_ >= 0) ::close(fd_);
}

Status SentJournal::append(const std::string& command_id) {
  if (command_id.empty() || command_id.find('\n') != std::string::npos) {
    throw std::invalid_argument("SentJournal::append: the id must be non-empty, on one line");
  }
  if (ids_.count(command_id)) return Status::Ok();
  const std::string line = command_id + "\n";
  std::size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return ioError(path_, "cannot append to the execution monitor's journal");
    done += static_cast<std::size_t>(n);
  }
  if (::fdatasync(fd_) != 0) return ioError(path_, "cannot sync the execution monitor's journal");
  ids_.insert(command_id);
  return Status::Ok();
}

}  // namespace tamp::execution_monitor
