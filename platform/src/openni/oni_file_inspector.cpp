#include "openni/oni_file_inspector.h"

#include <cstring>
#include <fstream>
#include <vector>

namespace mrgi::oni {
namespace {

constexpr uint32_t kRecordIntProperty = 3;
constexpr uint32_t kRecordNewData = 10;
constexpr uint32_t kRecordEnd = 11;
constexpr uint32_t kRecordNodeAdded = 13;
constexpr size_t kFileHeaderSize = 24;
constexpr size_t kRecordHeaderSize = 28;

template <class T>
T read_le(const std::vector<char>& d, size_t at) {
  T v{};
  std::memcpy(&v, d.data() + at, sizeof(T));  // x86/aarch64 are little-endian, as the format
  return v;
}

// A length-prefixed, NUL-terminated string inside a record's fields; empty if out of bounds.
std::string read_name(const std::vector<char>& d, size_t at, size_t end, size_t* after) {
  if (at + 4 > end) return {};
  const uint32_t len = read_le<uint32_t>(d, at);
  if (len == 0 || at + 4 + len > end) return {};
  *after = at + 4 + len;
  return std::string(d.data() + at + 4, strnlen(d.data() + at + 4, len));
}

}  // namespace

uint64_t FileSummary::int_property(uint32_t node, const std::string& name, uint64_t fallback) const {
  auto n = nodes.find(node);
  if (n == nodes.end()) return fallback;
  auto p = n->second.int_properties.find(name);
  return p == n->second.int_properties.end() ? fallback : p->second;
}

Expected<FileSummary> inspect_oni_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return fail(ErrorKind::NotFound, path + ": cannot open the OpenNI file");
  const std::streamoff size = in.tellg();
  if (size < std::streamoff(kFileHeaderSize))
    return fail(ErrorKind::BadInput, path + ": " + std::to_string(size) +
                                         " bytes is shorter than the 24-byte OpenNI file header (truncated)");
  std::vector<char> d(static_cast<size_t>(size));
  in.seekg(0);
  if (!in.read(d.data(), size)) return fail(ErrorKind::BadInput, path + ": read error");
  if (std::memcmp(d.data(), "NI10", 4) != 0)
    return fail(ErrorKind::BadInput, path + ": offset 0: magic is not \"NI10\" (not an OpenNI file, or corrupt)");

  FileSummary s;
  s.version_major = uint8_t(d[4]);
  s.version_minor = uint8_t(d[5]);
  s.max_timestamp_us = read_le<uint64_t>(d, 12);
  size_t at = kFileHeaderSize;
  bool ended = false;
  while (at < d.size()) {
    const std::string where = path + ": record " + std::to_string(s.record_count) + " at byte " + std::to_string(at);
    if (at + kRecordHeaderSize > d.size())
      return fail(ErrorKind::BadInput, where + ": the file ends inside the 28-byte record header (truncated)");
    if (std::memcmp(d.data() + at, "NIR\0", 4) != 0)
      return fail(ErrorKind::BadInput, where + ": record magic is not \"NIR\" (corrupt)");
    const uint32_t type = read_le<uint32_t>(d, at + 4);
    const uint32_t node = read_le<uint32_t>(d, at + 8);
    const uint64_t fields = read_le<uint32_t>(d, at + 12);
    const uint64_t payload = read_le<uint32_t>(d, at + 16);
    if (fields < kRecordHeaderSize)
      return fail(ErrorKind::BadInput, where + ": fields size " + std::to_string(fields) + " is below the header size 28 (corrupt)");
    const uint64_t end = at + fields + payload;
    if (end > d.size())
      return fail(ErrorKind::BadInput, where + ": record of " + std::to_string(fields + payload) +
                                           " bytes runs past the end of the file at byte " +
                                           std::to_string(d.size()) + " (truncated)");
    const size_t fields_end = at + size_t(fields);
    if (type == kRecordNodeAdded) {
      size_t after = 0;
      std::string name = read_name(d, at + kRecordHeaderSize, fields_end, &after);
      s.nodes[node].name = name;
      if (name.rfind("Depth", 0) == 0 && s.depth_node == 0) s.depth_node = node;
      if (name.rfind("Image", 0) == 0 && s.image_node == 0) s.image_node = node;
    } else if (type == kRecordIntProperty) {
      size_t after = 0;
      std::string name = read_name(d, at + kRecordHeaderSize, fields_end, &after);
      // {u32 value size = 8; u64 value}
      if (!name.empty() && after + 12 <= fields_end && read_le<uint32_t>(d, after) == 8)
        s.nodes[node].int_properties[name] = read_le<uint64_t>(d, after + 4);
    } else if (type == kRecordNewData) {
      ++s.nodes[node].data_records;
    } else if (type == kRecordEnd) {
      ended = true;
    }
    ++s.record_count;
    at = size_t(end);
    if (ended) break;
  }
  if (!ended)
    return fail(ErrorKind::BadInput, path + ": no End record after " + std::to_string(s.record_count) +
                                         " records (the file is truncated: OpenNI2 needs the seek table and End record at its tail)");
  return s;
}

}  // namespace mrgi::oni
