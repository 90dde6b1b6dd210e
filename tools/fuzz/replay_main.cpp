// A main() for the fuzz targets where libFuzzer is not available (a GCC build): runs the target
// once on every file named on the command line or found in a named folder (the seed corpora),
// which is how CTest checks every target on every build. Flags (arguments starting with '-', as
// libFuzzer's -runs=0) are ignored so one command line serves both builds.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

int run_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "%s: cannot be read\n", p.c_str());
    return 1;
  }
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int inputs = 0, failures = 0;
  for (int i = 1; i < argc; ++i) {
    if (argv[i][0] == '-') continue;
    const std::filesystem::path p(argv[i]);
    std::error_code ec;
    if (std::filesystem::is_directory(p, ec)) {
      for (const auto& e : std::filesystem::directory_iterator(p)) {
        if (!e.is_regular_file()) continue;
        failures += run_file(e.path());
        ++inputs;
      }
    } else {
      failures += run_file(p);
      ++inputs;
    }
  }
  std::printf("ran %d inputs\n", inputs);
  return failures == 0 ? 0 : 1;
}
