// What load_gltf reads before tinygltf sees a byte, and the limits it holds the file to. tinygltf
// parses JSON recursively (15,000 nested arrays overflow the stack), follows buffer and image
// URIs anywhere (`../../etc/hostname`, a FIFO that blocks for ever) and allocates what the file
// asks for; so the file is read here with a size cap, the JSON's nesting is bounded by a scan, and
// the loader's file access is confined to regular files in the model's own folder.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "image/file_io.h"
#include "mrgi/expected.h"

namespace mrgi::gltf {

// Input limits (README "Input limits"); beyond them the file is refused with BadInput naming
// the limit. Sized far above any asset meant for a headset: 1 GiB per file, 128 levels of JSON
// nesting (glTF files use under 10), 65,536 node visits and primitive instances, 16 M vertices.
constexpr uint64_t kMaxFileBytes = kMaxInputFileBytes;  // image/file_io.h
constexpr int kMaxJsonDepth = 128;
constexpr size_t kMaxNodeVisits = 1u << 16;
constexpr size_t kMaxPrimitives = 1u << 16;
constexpr size_t kMaxVertices = 1u << 24;

struct Input {
  std::vector<unsigned char> bytes;  // the whole file
  bool binary = false;               // .glb
  std::string base_dir;              // the model's folder (absolute): URIs resolve inside it
};

// Reads `path` (a regular file within kMaxFileBytes), checks a .glb's header and chunk sizes,
// and bounds the JSON's nesting depth. Errors name the file and the rule.
Expected<Input> read_input(const std::string& path, bool binary);

// Depth of the deepest array/object nesting in JSON text (strings and escapes skipped); stops
// counting past `limit` + 1.
int json_nesting_depth(const char* text, size_t size, int limit);

// File callbacks for tinygltf that open only regular files inside `base_dir` (symlinks resolved)
// within kMaxFileBytes, and never write. `base_dir` must outlive the loader.
tinygltf::FsCallbacks confined_fs(const std::string* base_dir);

// The loader's image decoder (TinyGLTF::SetImageLoader): PNG through libpng and JPEG through
// libjpeg-turbo (image/texture_decode.h), as 8-bit RGBA; any other format refused naming the
// image; the model's textures together capped at kMaxTextureBytes. `state` counts the bytes.
constexpr uint64_t kMaxTextureBytes = 1ull << 30;
struct ImageLoaderState {
  uint64_t bytes = 0;
};
bool load_image(tinygltf::Image* image, int index, std::string* err, std::string* warn, int req_width,
                int req_height, const unsigned char* bytes, int size, void* state);

}  // namespace mrgi::gltf
