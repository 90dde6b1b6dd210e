// Small file helpers shared by the image and scene loaders.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "mrgi/expected.h"

namespace mrgi {

// Whole file into memory. NotFound when it does not exist, BadInput when it cannot be read.
Expected<std::vector<uint8_t>> read_file_bytes(const std::string& path);

// Renames TMP over PATH (atomic on one filesystem), removing TMP on failure.
Status rename_into_place(const std::string& tmp, const std::string& path);

// Writes TEXT to PATH.tmp, then renames it to PATH.
Status write_text_file(const std::string& path, const std::string& text);

}  // namespace mrgi
