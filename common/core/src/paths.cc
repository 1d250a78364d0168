#include "tamp/core/paths.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "tamp/core/append_file.h"
#include "tamp/core/error.h"

namespace tamp {

std::filesystem::path configDir() {
  if (const char* env = std::getenv("TAMP_CONFIG_DIR"); env != nullptr && *env != '\0') return env;
  return TAMP_DEFAULT_CONFIG_DIR;
}

std::filesystem::path benchmarksDir() {
  if (const char* env = std::getenv("TAMP_BENCHMARKS_DIR"); env != nullptr && *env != '\0') {
    return env;
  }
  return TAMP_DEFAULT_BENCHMARKS_DIR;
}

std::filesystem::path resolveRelativeTo(const std::filesystem::path& base_file,
                                        const std::filesystem::path& relative) {
  if (relative.is_absolute()) return relative;
  return (base_file.parent_path() / relative).lexically_normal();
}

Result<std::string> readTextFile(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) {
    return Error(ErrorCode::kNotFound, "file does not exist", SourceLocation{file.string()});
  }
  if (std::filesystem::is_directory(file, ec)) {
    return Error(ErrorCode::kIo, "is a directory, expected a file", SourceLocation{file.string()});
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) return Error(ErrorCode::kIo, "cannot open for reading", SourceLocation{file.string()});
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return Error(ErrorCode::kIo, "read failed", SourceLocation{file.string()});
  return ss.str();
}

namespace {

Error ioError(const std::filesystem::path& path, const std::string& what) {
  return Error(ErrorCode::kIo, what + ": " + std::strerror(errno), SourceLocation{path.string()});
}

}  // namespace

Status writeFileAtomically(const std::filesystem::path& file, const std::string& text, const std::string& what) {
  const std::filesystem::path tmp = file.string() + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return ioError(tmp, "cannot write " + what);
  const bool ok = writeAll(fd, text) && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok) return ioError(tmp, "cannot write " + what);
  if (::rename(tmp.c_str(), file.c_str()) != 0) return ioError(file, "cannot replace " + what);
  return syncDirectory(file.parent_path(), what);
}

}  // namespace tamp
