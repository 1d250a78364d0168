// `tamp SUBCOMMAND ARGS...` runs the executable `tamp-SUBCOMMAND` that sits next to this binary
// (git-style). Each subcommand is its own lean executable, so `tamp plan` does not pay the start-up
// cost of libraries that only `tamp run` needs (PCL, OMPL, Fast DDS), and CLI11 is compiled once per
// subcommand in its own main.
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

fs::path selfDir() {
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path(".") : exe.parent_path();
}

std::vector<std::string> subcommands(const fs::path& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("tamp-", 0) == 0 && access(e.path().c_str(), X_OK) == 0) out.push_back(name.substr(5));
  }
  std::sort(out.begin(), out.end());
  return out;
}

int usage(const fs::path& dir, std::ostream& os) {
  os << "usage: tamp SUBCOMMAND [ARGS...]\n"
        "Conditional task and motion planning through an effort-based approach.\n\n"
        "Subcommands (each has --help):\n";
  for (const auto& s : subcommands(dir)) os << "  " << s << "\n";
  os << "\nExit codes: 0 success, 10-19 no solution, 20-29 out of time/memory, 30-39 input error,\n"
        "40-49 service unavailable, 50 an output could not be written.\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const fs::path dir = selfDir();
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h" ||
      std::string(argv[1]) == "help") {
    usage(dir, std::cout);
    return argc < 2 ? 30 : 0;
  }
  if (std::string(argv[1]) == "--version") {
    std::cout << "tamp " << TAMP_VERSION << "\n";
    return 0;
  }
  const std::string sub = argv[1];
  if (sub.find('/') != std::string::npos) {
    std::cerr << "tamp: invalid subcommand '" << sub << "'\n";
    return 30;
  }
  const fs::path target = dir / ("tamp-" + sub);
  std::vector<char*> args;
  std::string arg0 = "tamp " + sub;
  args.push_back(arg0.data());
  for (int i = 2; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  execv(target.c_str(), args.data());
  if (errno == ENOENT) {
    std::cerr << "tamp: unknown subcommand '" << sub << "'\n\n";
    usage(dir, std::cerr);
  } else {
    std::cerr << "tamp: cannot run " << target << ": " << std::strerror(errno) << "\n";
  }
  return 30;
}
