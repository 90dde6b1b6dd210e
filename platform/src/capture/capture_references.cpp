// Delta-stored references (mrgi/platform/capture_references.h): the codec, in-place conversion
// of a capture's references and export as plain PNGs.
#include "mrgi/platform/capture_references.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "capture/capture_text.h"

namespace mrgi {
namespace {

namespace fs = std::filesystem;

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

Status check_same_size(const ImageRGB8& a, const ImageRGB8& b, const char* what) {
  if (a.width != b.width || a.height != b.height || a.data.size() != b.data.size())
    return fail(ErrorKind::BadUsage, std::string(what) + ": " + std::to_string(a.width) + "x" +
                                         std::to_string(a.height) + " and the colour frame's " +
                                         std::to_string(b.width) + "x" + std::to_string(b.height) +
                                         " differ; a delta needs both the same size");
  return ok_status();
}

// NNNNNN.png <-> NNNNNN.delta.png (the names CaptureWriter gives).
std::string renamed_reference(const std::string& listed, ReferenceStorage to) {
  std::string stem = listed;
  if (is_delta_reference_path(stem))
    stem.resize(stem.size() - std::string(kDeltaReferenceSuffix).size());
  else if (ends_with(stem, ".png"))
    stem.resize(stem.size() - 4);
  return stem + (to == ReferenceStorage::Delta ? kDeltaReferenceSuffix : ".png");
}

std::string resolve(const fs::path& folder, const std::string& listed) {
  const fs::path p(listed);
  return (p.is_absolute() ? p : folder / p).lexically_normal().string();
}

Expected<std::vector<std::string>> read_raw_lines(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorKind::NotFound, path + ": cannot open");
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

std::string line_ref(const std::string& list_path, int line) { return list_path + ":" + std::to_string(line); }

}  // namespace

bool is_delta_reference_path(const std::string& path) {
  return ends_with(fs::path(path).filename().string(), kDeltaReferenceSuffix);
}

Expected<ImageRGB8> encode_reference_delta(const ImageRGB8& reference, const ImageRGB8& color) {
  MRGI_TRY(check_same_size(reference, color, "reference delta: the reference"));
  ImageRGB8 delta(reference.width, reference.height);
  for (size_t i = 0; i < delta.data.size(); ++i) delta.data[i] = uint8_t(reference.data[i] - color.data[i]);
  return delta;
}

Expected<ImageRGB8> decode_reference_delta(const ImageRGB8& delta, const ImageRGB8& color) {
  MRGI_TRY(check_same_size(delta, color, "reference delta: the delta"));
  ImageRGB8 reference(delta.width, delta.height);
  for (size_t i = 0; i < reference.data.size(); ++i) reference.data[i] = uint8_t(color.data[i] + delta.data[i]);
  return reference;
}

Expected<ReferenceConversion> convert_capture_references(const std::string& folder, ReferenceStorage storage) {
  // Refuse what the reader refuses before touching anything.
  auto reader = CaptureReader::open(folder);
  if (!reader) return reader.error();
  const fs::path dir(folder);
  const std::string list_path = (dir / "reference.txt").string();
  if (!capture::file_exists(list_path))
    return fail(ErrorKind::NotFound, list_path + ": missing; the capture has no references to convert");
  auto refs = capture::read_list(list_path, 1, 2, "timestamp path [mask_path]");
  if (!refs) return refs.error();
  auto colors = capture::read_list((dir / "rgb.txt").string(), 1, 1, "timestamp path");
  if (!colors) return colors.error();
  auto raw = read_raw_lines(list_path);
  if (!raw) return raw.error();

  ReferenceConversion result;
  std::vector<std::string> old_files;
  for (const capture::ListLine& line : *refs) {
    const std::string& listed = line.fields[0];
    const bool was_delta = is_delta_reference_path(listed);
    if (was_delta == (storage == ReferenceStorage::Delta)) {
      ++result.unchanged;
      continue;
    }
    const std::string where = line_ref(list_path, line.line);
    auto color_line = std::find_if(colors->begin(), colors->end(),
                                   [&](const capture::ListLine& c) { return c.timestamp == line.timestamp; });
    if (color_line == colors->end())
      return fail(ErrorKind::BadInput, where + ": rgb.txt has no frame at exactly timestamp " +
                                           capture::format_double(line.timestamp) +
                                           "; a delta reference is stored relative to that frame");
    auto color = load_png_rgb8(resolve(dir, color_line->fields[0]));
    if (!color) return color.error();
    const std::string old_path = resolve(dir, listed);
    auto stored = load_png_rgb8(old_path);
    if (!stored) return fail(ErrorKind::BadInput, where + ": " + stored.error().message);
    ImageRGB8 reference = std::move(*stored);
    if (was_delta) {
      auto decoded = decode_reference_delta(reference, *color);
      if (!decoded) return fail(ErrorKind::BadInput, where + ": " + decoded.error().message);
      reference = std::move(*decoded);
    }

    const std::string new_listed = renamed_reference(listed, storage);
    const std::string new_path = resolve(dir, new_listed);
    std::error_code ec;
    if (fs::exists(new_path, ec))
      return fail(ErrorKind::BadUsage, where + ": '" + new_path + "' already exists; converting would "
                                                                  "overwrite it (remove it first)");
    if (storage == ReferenceStorage::Delta) {
      auto delta = encode_reference_delta(reference, *color);
      if (!delta) return fail(ErrorKind::BadInput, where + ": " + delta.error().message);
      MRGI_TRY(write_png(new_path, *delta, PngEffort::Small));
    } else {
      MRGI_TRY(write_png(new_path, reference, PngEffort::Small));
    }
    // Read the new file back through the same decoding the reader uses: it must give exactly the
    // original pixels, or nothing is changed.
    auto back = load_png_rgb8(new_path);
    if (back && storage == ReferenceStorage::Delta) back = decode_reference_delta(*back, *color);
    if (!back || back->data != reference.data) {
      fs::remove(new_path, ec);
      return fail(ErrorKind::Device, where + ": '" + new_path + "' did not read back to the original "
                                                                "pixels; the capture is unchanged");
    }

    // Rebuild the line in CaptureWriter's layout ("timestamp path [mask]"), timestamp text kept.
    std::istringstream tokens((*raw)[size_t(line.line - 1)]);
    std::vector<std::string> fields;
    for (std::string t; tokens >> t;) fields.push_back(t);
    fields[1] = new_listed;
    std::string rebuilt = fields[0];
    for (size_t k = 1; k < fields.size(); ++k) rebuilt += " " + fields[k];
    (*raw)[size_t(line.line - 1)] = rebuilt;
    old_files.push_back(old_path);
    ++result.converted;
  }
  if (result.converted == 0) return result;
  std::string text;
  for (const std::string& l : *raw) text += l + "\n";
  MRGI_TRY(capture::write_text(list_path, text));
  for (const std::string& f : old_files) {
    std::error_code ec;
    fs::remove(f, ec);
    if (ec) return fail(ErrorKind::Device, f + ": converted, but the old file cannot be removed: " + ec.message());
  }
  return result;
}

Expected<size_t> export_references(const CaptureReader& capture, const std::string& dir) {
  std::error_code ec;
  if (fs::exists(dir, ec) && !(fs::is_directory(dir, ec) && fs::is_empty(dir, ec)))
    return fail(ErrorKind::BadUsage, dir + ": already exists and is not an empty folder; export writes "
                                           "into a new or empty folder");
  fs::create_directories(dir, ec);
  if (ec) return fail(ErrorKind::Device, dir + ": cannot create folder: " + ec.message());
  size_t written = 0;
  for (size_t i = 0; i < capture.frame_count(); ++i) {
    if (capture.entry(i).reference.empty()) continue;
    auto reference = capture.read_reference(i);
    if (!reference) return reference.error();
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", i);
    MRGI_TRY(write_png((fs::path(dir) / name).string(), *reference));
    ++written;
  }
  if (written == 0)
    return fail(ErrorKind::NotFound, capture.folder() + ": the capture has no reference frames to export");
  return written;
}

}  // namespace mrgi
