#include "scene/gltf_input.h"

#include "image/file_io.h"
#include "image/texture_decode.h"

#include <cstring>
#include <filesystem>

namespace mrgi::gltf {
namespace fs = std::filesystem;

namespace {

uint32_t le32(const unsigned char* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// The resolved path if it lies inside base (both made canonical as far as they exist).
bool inside(const std::string& base, const std::string& path, fs::path& resolved) {
  std::error_code ec;
  const fs::path b = fs::weakly_canonical(fs::path(base), ec);
  if (ec) return false;
  fs::path p(path);
  if (p.is_relative()) p = b / p;
  resolved = fs::weakly_canonical(p, ec);
  if (ec) return false;
  const std::string bs = b.string(), rs = resolved.string();
  return rs.size() > bs.size() && rs.compare(0, bs.size(), bs) == 0 && rs[bs.size()] == '/';
}

// Says whether the path names anything, so tinygltf goes on to read_whole, which refuses what
// lies outside the folder or is not a regular file with a message saying so (a plain "file not
// found" would hide why).
bool file_exists(const std::string& path, void* user) {
  const std::string& base = *static_cast<const std::string*>(user);
  fs::path p(path);
  if (p.is_relative()) p = fs::path(base) / p;
  std::error_code ec;
  return fs::exists(fs::symlink_status(p, ec));
}

std::string expand_path(const std::string& path, void*) { return path; }  // no ~ or $VAR

bool read_whole(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  const std::string& base = *static_cast<const std::string*>(user);
  fs::path resolved;
  if (!inside(base, path, resolved)) {
    if (err) *err += "'" + path + "' lies outside the model's folder " + base + " (refused)\n";
    return false;
  }
  auto bytes = read_file_bytes(resolved.string(), kMaxFileBytes);
  if (!bytes) {
    if (err) *err += "'" + path + "': " + bytes.error().message + "\n";
    return false;
  }
  *out = std::move(*bytes);
  return true;
}

bool write_whole(std::string* err, const std::string& path, const std::vector<unsigned char>&, void*) {
  if (err) *err += "'" + path + "': mrgi never writes glTF files\n";
  return false;
}

}  // namespace

int json_nesting_depth(const char* text, size_t size, int limit) {
  int depth = 0, deepest = 0;
  bool in_string = false;
  for (size_t i = 0; i < size; ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;  // skip the escaped character
      else if (c == '"') in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > deepest) deepest = depth;
      if (deepest > limit) return deepest;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

Expected<Input> read_input(const std::string& path, bool binary) {
  Input in;
  in.binary = binary;
  auto bytes = read_file_bytes(path, kMaxFileBytes);
  if (!bytes) return bytes.error();
  in.bytes = std::move(*bytes);
  std::error_code ec;
  in.base_dir = fs::weakly_canonical(fs::absolute(fs::path(path)).parent_path(), ec).string();
  if (ec) return fail(ErrorKind::BadInput, path + ": cannot resolve its folder: " + ec.message());
  const unsigned char* json = in.bytes.data();
  size_t json_size = in.bytes.size();
  if (binary) {
    // glb: 12-byte header (magic "glTF", version 2, total length), then the JSON chunk (length,
    // type "JSON"), padded; the BIN chunk follows.
    const size_t n = in.bytes.size();
    if (n < 20 || std::memcmp(in.bytes.data(), "glTF", 4) != 0)
      return fail(ErrorKind::BadInput, path + ": not a binary glTF (.glb header 'glTF' missing or file under 20 bytes)");
    const uint32_t version = le32(&in.bytes[4]), total = le32(&in.bytes[8]);
    const uint32_t chunk = le32(&in.bytes[12]), type = le32(&in.bytes[16]);
    if (version != 2)
      return fail(ErrorKind::BadInput, path + ": .glb version " + std::to_string(version) + " (only glTF 2.0 is read)");
    if (total > n)
      return fail(ErrorKind::BadInput, path + ": .glb header says " + std::to_string(total) +
                                           " bytes, the file has " + std::to_string(n) + " (truncated)");
    if (type != 0x4E4F534Au || uint64_t(chunk) + 20 > total)
      return fail(ErrorKind::BadInput, path + ": .glb first chunk is not a JSON chunk within the file "
                                              "(type or length out of range)");
    json = in.bytes.data() + 20;
    json_size = chunk;
  }
  const int depth = json_nesting_depth(reinterpret_cast<const char*>(json), json_size, kMaxJsonDepth);
  if (depth > kMaxJsonDepth)
    return fail(ErrorKind::BadInput, path + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) +
                                         " levels (limit; glTF files use under 10)");
  return in;
}

tinygltf::FsCallbacks confined_fs(const std::string* base_dir) {
  tinygltf::FsCallbacks cb;
  cb.FileExists = &file_exists;
  cb.ExpandFilePath = &expand_path;
  cb.ReadWholeFile = &read_whole;
  cb.WriteWholeFile = &write_whole;
  cb.user_data = const_cast<std::string*>(base_dir);
  return cb;
}

bool load_image(tinygltf::Image* image, int index, std::string* err, std::string*, int, int,
                const unsigned char* bytes, int size, void* state_ptr) {
  auto* state = static_cast<ImageLoaderState*>(state_ptr);
  const std::string which = "image " + std::to_string(index) + (image->uri.empty() ? "" : " ('" + image->uri + "')");
  if (!bytes || size <= 0) {
    if (err) *err += which + ": no image data\n";
    return false;
  }
  const size_t n = size_t(size);
  Expected<ImageRGBA8> decoded = fail(ErrorKind::BadInput, "");
  if (n >= 8 && bytes[0] == 0x89 && bytes[1] == 'P' && bytes[2] == 'N' && bytes[3] == 'G') {
    decoded = decode_png_rgba8(bytes, n);
  } else if (n >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF) {
    decoded = decode_jpeg_rgba8(bytes, n);
  } else {
    if (err) *err += which + ": not a PNG or JPEG (the only texture formats read)\n";
    return false;
  }
  if (!decoded) {
    if (err) *err += which + ": " + decoded.error().message + "\n";
    return false;
  }
  const uint64_t add = uint64_t(decoded->data.size());
  if (state && state->bytes + add > kMaxTextureBytes) {
    if (err) *err += which + ": the model's textures exceed " + std::to_string(kMaxTextureBytes) + " bytes (limit)\n";
    return false;
  }
  if (state) state->bytes += add;
  image->width = decoded->width;
  image->height = decoded->height;
  image->component = 4;
  image->bits = 8;
  image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  image->image = std::move(decoded->data);
  return true;
}

}  // namespace mrgi::gltf
