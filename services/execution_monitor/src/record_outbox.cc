#include "tamp/execution_monitor/record_outbox.h"

#include <algorithm>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "tamp/core/hex.h"

namespace tamp::execution_monitor {

namespace {

constexpr const char* kWhat = "the execution records' outbox";

bool validId(const std::string& id) {
  return !id.empty() && std::none_of(id.begin(), id.end(), [](char c) { return c == ' ' || c == '\n' || c == '\t' || c == '\r'; });
}

}  // namespace

Result<RecordOutbox> RecordOutbox::open(const std::filesystem::path& path) {
  auto read = readFileIfExists(path, kWhat);
  if (!read) return read.error();
  const std::string& text = *read;
  auto file = AppendFile::open(path, kWhat);
  if (!file) return file.error();
  RecordOutbox box(std::move(*file));
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
  if (start < text.size()) {
    if (Status s = box.file_.truncate(start); !s) return s.error();
  }
  (void)syncDirectory(path.parent_path(), kWhat);
  return box;
}

Result<bool> RecordOutbox::add(const std::string& record_id, const std::string& payload) {
  if (!validId(record_id)) {
    throw std::invalid_argument("RecordOutbox::add: a record id must be non-empty without whitespace, got '" +
                                record_id + "'");
  }
  if (pending_.count(record_id) || acked_.count(record_id)) return false;
  if (Status s = file_.append("r " + record_id + " " + toHex(payload) + "\n", true); !s) return s.error();
  pending_[record_id] = Entry{record_id, payload, -std::numeric_limits<double>::infinity(), 0};
  order_.push_back(record_id);
  return true;
}

bool RecordOutbox::acknowledge(const std::string& record_id) {
  if (!validId(record_id) || !pending_.count(record_id)) return false;
  pending_.erase(record_id);
  acked_.insert(record_id);
  (void)file_.append("a " + record_id + "\n", false);  // lost: one resend after a restart
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
