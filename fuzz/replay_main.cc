// A libFuzzer-compatible driver for builds without libFuzzer (g++, CI): runs
// LLVMFuzzerTestOneInput once on every file named on the command line, and on
// every file (recursively) of every directory named there. Arguments starting
// with '-' (libFuzzer flags) are ignored. Exits 0 when every input ran; a
// crash, a sanitizer report or a failed check of the target aborts as it would
// under libFuzzer. Used by the CTest smoke tests (fuzz_*_corpus) to replay the
// committed corpora, and by hand to replay one crash input:
//   build/fuzz/fuzz_bvh_replay fuzz/corpus/fuzz_bvh/crash-...
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
extern "C" __attribute__((weak)) int LLVMFuzzerInitialize(int* argc, char*** argv);

namespace {

bool read_file(const std::filesystem::path& path, std::vector<uint8_t>* out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return !in.bad();
}

}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  if (LLVMFuzzerInitialize) LLVMFuzzerInitialize(&argc, &argv);
  std::vector<fs::path> files;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (!arg.empty() && arg[0] == '-') continue;
    std::error_code ec;
    if (fs::is_directory(arg, ec)) {
      for (const auto& entry : fs::recursive_directory_iterator(arg))
        if (entry.is_regular_file()) files.push_back(entry.path());
    } else {
      files.push_back(arg);
    }
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    std::fprintf(stderr, "%s: no input files\n", argv[0]);
    return 2;
  }
  const auto start = std::chrono::steady_clock::now();
  std::vector<uint8_t> bytes;
  for (const fs::path& f : files) {
    if (!read_file(f, &bytes)) {
      std::fprintf(stderr, "%s: cannot read %s\n", argv[0], f.c_str());
      return 2;
    }
    // A copy of exactly the file's size, so that a read past the end is a
    // heap overflow that AddressSanitizer sees.
    std::vector<uint8_t> input(bytes);
    LLVMFuzzerTestOneInput(input.empty() ? nullptr : input.data(), input.size());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s: %zu inputs ran in %.2f s\n", argv[0], files.size(), seconds);
  return 0;
}
