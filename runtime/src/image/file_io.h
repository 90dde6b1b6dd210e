// Small file helpers shared by the image and scene loaders.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "mrgi/expected.h"

namespace mrgi {

// Input files are refused above this size before anything is allocated (README "Input limits").
constexpr uint64_t kMaxInputFileBytes = 1ull << 30;

// Whole file into memory. NotFound when it does not exist or is not a regular file (a FIFO
// would block the open), BadInput when it is larger than `max_bytes` or cannot be read.
Expected<std::vector<uint8_t>> read_file_bytes(const std::string& path,
                                               uint64_t max_bytes = kMaxInputFileBytes);

// Renames TMP over PATH (atomic on one filesystem), removing TMP on failure.
Status rename_into_place(const std::string& tmp, const std::string& path);

// Writes TEXT to PATH.tmp, then renames it to PATH.
Status write_text_file(const std::string& path, const std::string& text);

}  // namespace mrgi
