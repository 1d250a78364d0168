#include "tamp/execution_monitor/sent_journal.h"

#include <stdexcept>
#include <utility>

namespace tamp::execution_monitor {

namespace {

constexpr const char* kWhat = "the execution monitor's journal";

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

}  // namespace

Result<SentJournal> SentJournal::open(const std::filesystem::path& path) {
  auto text = readFileIfExists(path, kWhat);
  if (!text) return text.error();
  auto file = AppendFile::open(path, kWhat);
  if (!file) return file.error();
  // A torn last line is cut off: completing it with a newline would turn the fragment into an
  // id on the next open ("m3-e1" torn from "m3-e12"), and a command with that id would then pass
  // for one sent before, not validated again.
  if (!text->empty() && text->back() != '\n') {
    const std::size_t nl = text->rfind('\n');
    if (Status s = file->truncate(nl == std::string::npos ? 0 : nl + 1); !s) return s.error();
  }
  (void)syncDirectory(path.parent_path(), kWhat);
  return SentJournal(std::move(*file), completeLines(*text));
}

SentJournal::SentJournal(AppendFile file, std::vector<std::string> previous)
    : file_(std::move(file)), previous_(std::move(previous)) {
  ids_.insert(previous_.begin(), previous_.end());
}

Status SentJournal::append(const std::string& command_id) {
  if (command_id.empty() || command_id.find('\n') != std::string::npos) {
    throw std::invalid_argument("SentJournal::append: the id must be non-empty, on one line");
  }
  if (ids_.count(command_id)) return Status::Ok();
  if (Status s = file_.append(command_id + "\n", true); !s) return s;
  ids_.insert(command_id);
  return Status::Ok();
}

}  // namespace tamp::execution_monitor
