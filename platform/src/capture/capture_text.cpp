#include "capture/capture_text.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace mrgi::capture {

bool parse_double(std::string_view token, double* out) {
  if (token.empty()) return false;
  const char* first = token.data();
  if (*first == '+') ++first;  // from_chars refuses a leading '+', TUM files never have one
  double v = 0.0;
  auto [ptr, ec] = std::from_chars(first, token.data() + token.size(), v);
  if (ec != std::errc() || ptr != token.data() + token.size() || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

std::string format_double(double v) {
  char buf[64];
  auto [ptr, ec] = std::to_chars(buf, buf + sizeof(buf), v);
  return ec == std::errc() ? std::string(buf, ptr) : std::string("nan");
}

Expected<std::vector<ListLine>> read_list(const std::string& path, size_t min_fields, size_t max_fields,
                                          const char* format) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))  // a FIFO would block the open for ever
    return fail(ErrorKind::NotFound, path + ": does not exist or is not a regular file");
  std::ifstream in(path);
  if (!in) return fail(ErrorKind::NotFound, path + ": file does not exist or cannot be read");
  std::vector<ListLine> out;
  std::string text;
  int line_no = 0;
  while (std::getline(in, text)) {
    ++line_no;
    if (!text.empty() && text.back() == '\r') text.pop_back();  // lists written on Windows
    // A NUL byte would cut a path short where the file system reads it, naming another file.
    if (text.find('\0') != std::string::npos)
      return fail(ErrorKind::BadInput, path + ":" + std::to_string(line_no) +
                                           ": holds a NUL byte (lists are text; a path cannot contain one)");
    std::istringstream words(text);
    std::vector<std::string> tokens;
    for (std::string w; words >> w;) tokens.push_back(w);
    if (tokens.empty() || tokens[0][0] == '#') continue;
    const std::string where = path + ":" + std::to_string(line_no) + ": ";
    if (tokens.size() < 1 + min_fields || tokens.size() > 1 + max_fields)
      return fail(ErrorKind::BadInput, where + "expected '" + format + "', got " +
                                           std::to_string(tokens.size()) + " field" +
                                           (tokens.size() == 1 ? "" : "s"));
    ListLine entry;
    entry.line = line_no;
    if (!parse_double(tokens[0], &entry.timestamp))
      return fail(ErrorKind::BadInput, where + "timestamp '" + tokens[0] +
                                           "' is not a finite number (expected '" + format + "')");
    if (!out.empty() && !(entry.timestamp > out.back().timestamp))
      return fail(ErrorKind::BadInput, where + "timestamp " + tokens[0] + " is not after line " +
                                           std::to_string(out.back().line) + "'s " +
                                           format_double(out.back().timestamp) +
                                           " (timestamps must strictly increase)");
    entry.fields.assign(tokens.begin() + 1, tokens.end());
    out.push_back(std::move(entry));
  }
  if (in.bad()) return fail(ErrorKind::BadInput, path + ": read failed");
  return out;
}

Status write_text(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return fail(ErrorKind::Device, path + ": cannot open " + tmp + " for writing");
    out << text;
    out.flush();
    if (!out) return fail(ErrorKind::Device, path + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) return fail(ErrorKind::Device, path + ": cannot rename " + tmp + ": " + ec.message());
  return ok_status();
}

bool file_exists(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

}  // namespace mrgi::capture
