/// \file
/// A tool's output folder (`--out DIR`), built as DIR.partial and moved into place at the end, so
/// nothing half-written is ever left as DIR. It only ever replaces or deletes what an mrgi tool
/// created: a folder holding the marker file `.mrgi-output` (written first into every
/// DIR.partial, and so into every finished DIR), or an empty folder. Everything else is refused
/// with a message, untouched:
///   - DIR or DIR.partial exists and is not a directory, is a symlink, or is a directory without
///     the marker (user data, or an output of an mrgi version before the marker: remove it by
///     hand or choose another folder);
///   - DIR is the file-system root, the home directory, or the current directory or one of its
///     parents (replacing it would delete what the user is working in).
///
/// A run that fails (the OutputDir is destroyed without commit()) removes its own DIR.partial.
#pragma once
#include <string>

#include "mrgi/expected.h"
#include "mrgi/export.h"

namespace mrgi {

class MRGI_API OutputDir {
 public:
  static constexpr const char* kMarker = ".mrgi-output";
  /// `option` names the flag in messages ("--out").
  static Expected<OutputDir> begin(const std::string& dir, const std::string& option = "--out");
  OutputDir(OutputDir&& other) noexcept;
  OutputDir& operator=(OutputDir&& other) noexcept;
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;
  ~OutputDir();

  const std::string& dir() const { return dir_; }          ///< absolute, normalised
  const std::string& partial() const { return partial_; }  ///< write the outputs here
  /// Replaces DIR (when it is still ours or empty) with DIR.partial. After it the OutputDir owns
  /// nothing.
  Status commit();

 private:
  OutputDir() = default;
  void abandon();
  std::string dir_, partial_, option_;
  bool active_ = false;
};

/// Whether `path` is a directory this program may replace: empty, or holding the marker.
MRGI_API bool is_replaceable_output(const std::string& path);

}  // namespace mrgi
