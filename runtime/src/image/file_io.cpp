#include "image/file_io.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

namespace mrgi {

Expected<std::vector<uint8_t>> read_file_bytes(const std::string& path, uint64_t max_bytes) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    return fail(ErrorKind::NotFound, path + ": file does not exist (or is not a regular file)");
  const uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) return fail(ErrorKind::BadInput, path + ": cannot read its size: " + ec.message());
  if (size > max_bytes)
    return fail(ErrorKind::BadInput, path + ": " + std::to_string(size) + " bytes, over the limit of " +
                                         std::to_string(max_bytes));
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorKind::BadInput, path + ": cannot open for reading: " + std::strerror(errno));
  std::vector<uint8_t> bytes(static_cast<size_t>(size));
  if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size)))
    return fail(ErrorKind::BadInput, path + ": read failed");
  return bytes;
}

Status rename_into_place(const std::string& tmp, const std::string& path) {
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    return fail(ErrorKind::Device, path + ": cannot rename " + tmp + " into place: " + ec.message());
  }
  return ok_status();
}

Status write_text_file(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return fail(ErrorKind::Device, path + ": cannot open " + tmp + " for writing");
    out << text;
    out.flush();
    if (!out) {
      out.close();
      std::remove(tmp.c_str());
      return fail(ErrorKind::Device, path + ": write failed");
    }
  }
  return rename_into_place(tmp, path);
}

}  // namespace mrgi
