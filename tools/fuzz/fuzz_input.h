// Shared by the fuzz targets (tools/fuzz/README.md): every parser under test reads files, so an
// input is written to a file in this process's own temporary folder first (unique per process,
// removed at exit) and the parser is called on its path, as mrgi calls it.
#pragma once
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace mrgi::fuzz {

class InputFolder {
 public:
  static InputFolder& get() {
    static InputFolder folder;
    return folder;
  }
  const std::filesystem::path& path() const { return path_; }
  // Writes DATA to NAME inside the folder (replacing it) and returns its path.
  std::string write(const std::string& name, const uint8_t* data, size_t size) const {
    const std::filesystem::path p = path_ / name;
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    return p.string();
  }
  ~InputFolder() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }

 private:
  InputFolder() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("mrgi-fuzz-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  std::filesystem::path path_;
};

inline bool starts_with(const uint8_t* data, size_t size, const char* magic) {
  const std::string m(magic);
  return size >= m.size() && std::equal(m.begin(), m.end(), reinterpret_cast<const char*>(data));
}

}  // namespace mrgi::fuzz
