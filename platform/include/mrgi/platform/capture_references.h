/// \file
/// Reference frames stored as deltas (capture format v1, mrgi/platform/capture.h).
///
/// A path-traced reference G and the camera frame C of the same timestamp are rendered with the
/// same random numbers, so every pixel the virtual objects do not affect is exactly equal, and the
/// rest differs by a small amount. Storing D = (G - C) mod 256 per 8-bit channel is lossless
/// (G = (C + D) mod 256) and its PNG is 35-65 % smaller than G's, which keeps the bundled suite
/// inside the repository's size budget. A reference file named *.delta.png holds D; any other
/// name holds G itself.
#pragma once
#include <string>

#include "mrgi/expected.h"
#include "mrgi/export.h"
#include "mrgi/image.h"
#include "mrgi/platform/capture.h"

namespace mrgi {

inline constexpr const char* kDeltaReferenceSuffix = ".delta.png";

/// True when PATH's file name ends in ".delta.png".
MRGI_API bool is_delta_reference_path(const std::string& path);

/// D = (reference - color) mod 256 per channel. BadUsage when the sizes differ.
MRGI_API Expected<ImageRGB8> encode_reference_delta(const ImageRGB8& reference, const ImageRGB8& color);
/// reference = (color + delta) mod 256 per channel. BadUsage when the sizes differ.
MRGI_API Expected<ImageRGB8> decode_reference_delta(const ImageRGB8& delta, const ImageRGB8& color);

struct ReferenceConversion {
  size_t converted = 0;   ///< references rewritten (and verified) in the requested storage
  size_t unchanged = 0;   ///< references already stored that way
};

/// Rewrites the references of the capture in FOLDER in place to STORAGE: for each reference.txt
/// line, writes the new file (NNNNNN.png <-> NNNNNN.delta.png, the same bytes CaptureWriter would
/// write), reads it back and checks it decodes to exactly the original pixels, then rewrites
/// reference.txt (write-then-rename) and only then removes the old files. An error part-way leaves
/// the old reference.txt and files in place, so the capture stays valid.
MRGI_API Expected<ReferenceConversion> convert_capture_references(const std::string& folder, ReferenceStorage storage);

/// Writes every reference of CAPTURE as a plain 8-bit RGB PNG DIR/NNNNNN.png (NNNNNN = the frame
/// index), reconstructing delta references; DIR is created and must not hold files yet. Returns the
/// number written.
MRGI_API Expected<size_t> export_references(const CaptureReader& capture, const std::string& dir);

}  // namespace mrgi
