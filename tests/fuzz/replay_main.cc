// Replays a fuzz target without libFuzzer (gcc builds, CI): every file of the given corpus paths,
// then `--mutations N` deterministic mutations of each (bit flips, random bytes, inserted and
// erased ranges, truncation, CDR-length-like 32-bit values such as 0xffffffff, NaN bytes). The
// target must return normally: a crash, an abort or an escaped exception fails the run (and the
// ctest that runs it). With `--write-seeds DIR` a target that defines TampFuzzWriteSeeds() writes
// its seed corpus there (the IDL target: serialised valid messages).
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
extern "C" int TampFuzzWriteSeeds(const char* dir) __attribute__((weak));

namespace {

using Bytes = std::vector<uint8_t>;

void run(const Bytes& b) { (void)LLVMFuzzerTestOneInput(b.empty() ? nullptr : b.data(), b.size()); }

Bytes mutate(Bytes b, std::mt19937_64& rng) {
  auto pick = [&](size_t n) { return n == 0 ? size_t{0} : static_cast<size_t>(rng() % n); };
  const int ops = 1 + static_cast<int>(rng() % 4);
  for (int k = 0; k < ops; ++k) {
    switch (rng() % 8) {
      case 0:  // flip a bit
        if (!b.empty()) b[pick(b.size())] ^= static_cast<uint8_t>(1u << (rng() % 8));
        break;
      case 1:  // a random byte
        if (!b.empty()) b[pick(b.size())] = static_cast<uint8_t>(rng());
        break;
      case 2: {  // insert bytes
        const size_t at = pick(b.size() + 1), n = 1 + pick(8);
        Bytes ins(n);
        for (auto& x : ins) x = static_cast<uint8_t>(rng());
        b.insert(b.begin() + static_cast<long>(at), ins.begin(), ins.end());
        break;
      }
      case 3: {  // erase a range
        if (b.empty()) break;
        const size_t at = pick(b.size()), n = 1 + pick(std::min<size_t>(b.size() - at, 64));
        b.erase(b.begin() + static_cast<long>(at), b.begin() + static_cast<long>(std::min(b.size(), at + n)));
        break;
      }
      case 4:  // truncate
        b.resize(pick(b.size() + 1));
        break;
      case 5: {  // duplicate a range (repeated keys, nested lists)
        if (b.empty()) break;
        const size_t at = pick(b.size()), n = 1 + pick(std::min<size_t>(b.size() - at, 128));
        Bytes copy(b.begin() + static_cast<long>(at), b.begin() + static_cast<long>(std::min(b.size(), at + n)));
        const size_t to = pick(b.size() + 1);
        b.insert(b.begin() + static_cast<long>(to), copy.begin(), copy.end());
        break;
      }
      case 6: {  // an interesting 32-bit value (sequence lengths, enums)
        static const uint32_t kValues[] = {0u, 1u, 0x7fu, 0xffu, 0x7fffffffu, 0x80000000u, 0xffffffffu, 0x10000u};
        if (b.size() < 4) break;
        const uint32_t v = kValues[rng() % std::size(kValues)];
        std::memcpy(b.data() + pick(b.size() - 3), &v, 4);
        break;
      }
      default: {  // a NaN or an infinity
        if (b.size() < 8) break;
        const double v = rng() % 2 ? std::numeric_limits<double>::quiet_NaN() : std::numeric_limits<double>::infinity();
        std::memcpy(b.data() + pick(b.size() - 7), &v, 8);
        break;
      }
    }
  }
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  long mutations = 0;
  uint64_t seed = 1;
  std::vector<std::filesystem::path> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--mutations" && i + 1 < argc) {
      mutations = std::stol(argv[++i]);
    } else if (a == "--seed" && i + 1 < argc) {
      seed = std::stoull(argv[++i]);
    } else if (a == "--write-seeds" && i + 1 < argc) {
      if (!TampFuzzWriteSeeds) {
        std::cerr << "this target has no seed writer\n";
        return 2;
      }
      return TampFuzzWriteSeeds(argv[++i]);
    } else if (std::filesystem::is_directory(a)) {
      for (const auto& e : std::filesystem::directory_iterator(a)) {
        if (e.is_regular_file()) files.push_back(e.path());
      }
    } else if (std::filesystem::is_regular_file(a)) {
      files.push_back(a);
    } else {
      std::cerr << "no such file or directory: " << a << "\n";
      return 2;
    }
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    std::cerr << "usage: " << argv[0] << " [--mutations N] [--seed S] CORPUS_DIR_OR_FILE...\n";
    return 2;
  }
  const auto t0 = std::chrono::steady_clock::now();
  long inputs = 0;
  for (size_t f = 0; f < files.size(); ++f) {
    std::ifstream in(files[f], std::ios::binary);
    const Bytes original((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    run(original);
    ++inputs;
    std::mt19937_64 rng(seed * 1000003u + f);
    Bytes current = original;
    for (long m = 0; m < mutations; ++m) {
      // Mostly from the original, sometimes stacked on the last mutant (deeper damage).
      current = mutate(rng() % 4 == 0 ? current : original, rng);
      run(current);
      ++inputs;
    }
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("replayed %ld inputs (%zu seed files, %ld mutations each) in %.2f s without a crash\n", inputs,
              files.size(), mutations, s);
  return 0;
}
