#include "tamp/execution_monitor/record_outbox.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "tamp/core/hex.h"

namespace tamp::execution_monitor {

namespace {

Error ioError(const std::filesystem::path& path, const std::string& what) {
  return Error(ErrorCode::kIo, what + ": " + std::strerror(errno), SourceLocation{path.string()});
}

bool validId(const std::string& id) {
  return !id.empty() && std::none_of(id.begin(), id.end(), [](char c) { return c == ' ' || c == '\n' || c == '\t' || c == '\r'; });
}

void syncDirectory(const std::filesystem::path& dir) {
  const int d = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (d < 0) return;
  (void)::fsync(d);
  ::close(d);
}

}  // namespace

Result<RecordOutbox> RecordOutbox::open(const std::filesystem::path& path) {
  std::string text;
  if (std::filesystem::exists(path)) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return ioError(path, "cannot read the execution records' outbox");
    std::ostringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) return ioError(path, "cannot open the execution records' outbox for appending");
  RecordOutbox box(path, fd);
  // Complete lines only: a last line without its newline was torn by a crash.
  std::size_t start = 0;
  int line_no = 0;
  for (std::size_t nl = text.find('\n'); nl != std::string::npos; nl = text.find('\n', start)) {
    const std::string line = text.substr(start, nl - start);
    start = nl + 1;
    ++line_no;
    if (line.empty()) continue;
    std::istringstream fields(line);
    std::string kind, id, hex;
    fields >> kind >> id >> hex;
    std::optional<std::string> payload = kind == "r" ? fromHex(hex) : std::optional<std::string>(std::string());
    if ((kind != "r" && kind != "a") || !validId(id) || !payload) {
      return Error(ErrorCode::kParseError, "not an outbox event: '" + line.substr(0, 80) + "'",
                   SourceLocation{path.string(), line_no, 0, ""});
    }
    if (kind == "a") {
      box.pending_.erase(id);
      box.acked_.insert(id);
    } else if (!box.acked_.count(id) && !box.pending_.count(id)) {
      box.pending_[id] = Entry{id, std::move(*payload), -std::numeric_limits<double>::infinity(), 0};
      box.order_.push_back(id);
    }
  }
  // A torn last line is cut off so that the next event starts on a line of its own.
  if (start < text.size() && ::ftruncate(fd, static_cast<off_t>(start)) != 0) {
    return ioError(path, "cannot cut the torn last line off the execution records' outbox");
  }
  syncDirectory(path.parent_path());
  return box;
}

RecordOutbox::RecordOutbox(std::filesystem::path path, int fd) : path_(std::move(path)), fd_(fd) {}

RecordOutbox::RecordOutbox(RecordOutbox&& o) noexcept
    : path_(std::move(o.path_)),
      fd_(std::exchange(o.fd_, -1)),
      pending_(std::move(o.pending_)),
      order_(std::move(o.order_)),
      acked_(std::move(o.acked_)) {}

RecordOutbox& RecordOutbox::operator=(RecordOutbox&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(o.path_);
    fd_ = std::exchange(o.fd_, -1);
    pending_ = std::move(o.pending_);
    order_ = std::move(o.order_);
    acked_ = std::move(o.acked_);
  }
  return *this;
}

RecordOutbox::~RecordOutbox() {
  if (fd_ >= 0) ::close(fd_);
}

Status RecordOutbox::appendLine(const std::string& line, bool sync) {
  if (fd_ < 0) return Status::Ok();
  std::size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return ioError(path_, "cannot append to the execution records' outbox");
    done += static_cast<std::size_t>(n);
  }
  if (sync && ::fdatasync(fd_) != 0) return ioError(path_, "cannot sync the execution records' outbox");
  return Status::Ok();
}

Result<bool> RecordOutbox::add(const std::string& record_id, const std::string& payload) {
  if (!validId(record_id)) {
    throw std::invalid_argument("RecordOutbox::add: a record id must be non-empty without whitespace, got '" +
                                record_id + "'");
  }
  if (pending_.count(record_id) || acked_.count(record_id)) return false;
  if (Status s = appendLine("r " + record_id + " " + toHex(payload) + "\n", true); !s) return s.error();
  pending_[record_id] = Entry{record_id, payload, -std::numeric_limits<double>::infinity(), 0};
  order_.push_back(record_id);
  return true;
}

bool RecordOutbox::acknowledge(const std::string& record_id) {
  if (!validId(record_id) || !pending_.count(record_id)) return false;
  pending_.erase(record_id);
  acked_.insert(record_id);
  (void)appendLine("a " + record_id + "\n", false);  // lost: one resend after a restart
  return true;
}

std::vector<RecordOutbox::Entry> RecordOutbox::due(double now, double resend_period_s) {
  std::vector<Entry> out;
  std::vector<std::string> still;
  for (const auto& id : order_) {
    auto it = pending_.find(id);
    if (it == pending_.end()) continue;  // acknowledged
    still.push_back(id);
    Entry& e = it->second;
    if (e.sends > 0 && e.last_sent > now - resend_period_s) continue;
    e.last_sent = now;
    ++e.sends;
    out.push_back(e);
  }
  order_ = std::move(still);
  return out;
}

}  // namespace tamp::execution_monitor
