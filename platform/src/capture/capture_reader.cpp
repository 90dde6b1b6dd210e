// Capture format v1 reader. How the streams are tied to the colour frames:
//   depth      TUM associate.py: every (colour, depth) pair closer than 0.02 s is a candidate;
//              candidates are taken closest first, each frame used at most once. Colour frames
//              left without depth are dropped and counted (TUM sequences have some); a capture
//              where none match is refused.
//   poses      groundtruth.txt is interpolated at the colour timestamp: linear in translation,
//              slerp in rotation, between the two poses around it. A pose whose timestamp equals
//              the colour timestamp is used exactly as written. Before the first or after the
//              last pose, the end pose is used if it is within 0.02 s; otherwise, and inside
//              gaps longer than 0.5 s (motion-capture dropouts), the frame has no pose.
//   env        each colour frame takes the env image with the nearest timestamp (no limit: a
//              static environment is one env.txt line).
//   reference  each reference.txt line belongs to the colour frame nearest in time, which must be
//              within 0.02 s; a line with no such colour frame is refused. A *.delta.png
//              reference is decoded against the colour frame of exactly its timestamp
//              (mrgi/platform/capture_references.h), so that frame must exist.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "capture/capture_text.h"
#include "mrgi/platform/capture.h"
#include "mrgi/platform/capture_references.h"

namespace mrgi {
namespace {

namespace fs = std::filesystem;

constexpr double kMaxAssociationGap = 0.02;   // s, TUM associate.py's default max_difference
constexpr double kMaxPoseGap = 0.5;           // s, longest groundtruth gap interpolated across
constexpr double kQuaternionTolerance = 1e-3;

struct TimedPose {
  double t;
  Pose pose;
};

std::string resolve(const std::string& folder, const std::string& listed) {
  const fs::path p(listed);
  return (p.is_absolute() ? p : fs::path(folder) / p).lexically_normal().string();
}

// Whether an optional file of the capture (capture.json, groundtruth.txt, scene.json, ...) is
// there: false when nothing is at PATH, true for a regular file (or a link to one), and an error
// for anything else: a folder, a FIFO or a dangling link named like the file would otherwise be
// skipped without a word (a scene.json folder rendered no object).
Expected<bool> optional_file(const std::string& path) {
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(path, ec);
  if (ec || link.type() == fs::file_type::not_found) return false;
  const fs::file_status target = fs::status(path, ec);
  if (target.type() == fs::file_type::regular) return true;
  if (link.type() == fs::file_type::symlink && (ec || target.type() == fs::file_type::not_found))
    return fail(ErrorKind::BadInput, path + ": a dangling symbolic link (it must be a regular file or absent)");
  return fail(ErrorKind::BadInput, path + ": not a regular file (a " +
                                       (target.type() == fs::file_type::directory ? "folder" : "special file") +
                                       "); it must be a regular file or absent");
}

// Resolves each line's path fields and checks the files: relative paths inside the capture
// folder (no absolute path, no '..' out of it: a list must not read other files of the
// machine), each a regular file.
Status check_listed_files(const std::string& list_path, const std::string& folder,
                          std::vector<capture::ListLine>* lines) {
  for (auto& line : *lines) {
    for (auto& field : line.fields) {
      const std::string where = list_path + ":" + std::to_string(line.line) + ": listed file '" + field + "'";
      const fs::path rel = fs::path(field).lexically_normal();
      if (rel.is_absolute() || rel.empty() || *rel.begin() == "..")
        return fail(ErrorKind::BadInput, where + " is not a relative path inside the capture folder");
      const std::string abs = resolve(folder, field);
      std::error_code ec;
      if (!fs::exists(abs, ec))
        return fail(ErrorKind::NotFound, where + " does not exist (looked for " + abs + ")");
      if (!capture::file_exists(abs)) return fail(ErrorKind::BadInput, where + " is not a regular file");
      field = abs;
    }
  }
  return ok_status();
}

Expected<std::vector<capture::ListLine>> read_image_list(const std::string& folder, const char* name,
                                                         size_t max_fields, const char* format) {
  const std::string path = (fs::path(folder) / name).string();
  auto lines = capture::read_list(path, 1, max_fields, format);
  if (!lines) return lines.error();
  MRGI_TRY(check_listed_files(path, folder, &*lines));
  return lines;
}

Expected<std::vector<TimedPose>> read_groundtruth(const std::string& path) {
  auto lines = capture::read_list(path, 7, 7, "timestamp tx ty tz qx qy qz qw");
  if (!lines) return lines.error();
  std::vector<TimedPose> poses;
  static const char* kNames[7] = {"tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  for (const auto& line : *lines) {
    double v[7];
    for (int i = 0; i < 7; ++i)
      if (!capture::parse_double(line.fields[size_t(i)], &v[i]))
        return fail(ErrorKind::BadInput, path + ":" + std::to_string(line.line) + ": " + kNames[i] +
                                             " '" + line.fields[size_t(i)] + "' is not a finite number");
    const glm::dquat q(v[6], v[3], v[4], v[5]);
    const double len = std::sqrt(glm::dot(q, q));
    if (std::abs(len - 1.0) > kQuaternionTolerance)
      return fail(ErrorKind::BadInput, path + ":" + std::to_string(line.line) +
                                           ": quaternion (qx qy qz qw) has length " +
                                           capture::format_double(len) +
                                           "; it must be unit length within 0.001");
    TimedPose p;
    p.t = line.timestamp;
    p.pose.translation = glm::dvec3(v[0], v[1], v[2]);
    p.pose.rotation = q;
    poses.push_back(p);
  }
  return poses;
}

std::optional<Pose> pose_at(const std::vector<TimedPose>& gt, double t) {
  if (gt.empty()) return std::nullopt;
  auto it = std::lower_bound(gt.begin(), gt.end(), t, [](const TimedPose& p, double v) { return p.t < v; });
  if (it != gt.end() && it->t == t) return it->pose;
  if (it == gt.begin()) return gt.front().t - t <= kMaxAssociationGap ? std::optional(gt.front().pose) : std::nullopt;
  if (it == gt.end()) return t - gt.back().t <= kMaxAssociationGap ? std::optional(gt.back().pose) : std::nullopt;
  const TimedPose& a = *(it - 1);
  const TimedPose& b = *it;
  if (b.t - a.t > kMaxPoseGap) return std::nullopt;
  const double u = (t - a.t) / (b.t - a.t);
  Pose p;
  p.translation = glm::mix(a.pose.translation, b.pose.translation, u);
  p.rotation = glm::normalize(glm::slerp(glm::normalize(a.pose.rotation), glm::normalize(b.pose.rotation), u));
  return p;
}

// Index of the entry in the sorted `times` nearest to t, or -1 when `times` is empty.
long nearest_index(const std::vector<double>& times, double t) {
  if (times.empty()) return -1;
  auto it = std::lower_bound(times.begin(), times.end(), t);
  if (it == times.end()) return long(times.size()) - 1;
  if (it == times.begin()) return 0;
  return (t - *(it - 1) <= *it - t) ? long(it - times.begin()) - 1 : long(it - times.begin());
}

struct Match {
  size_t color, depth;
};

// TUM associate.py: candidate pairs within the gap, closest first, each frame used once.
std::vector<Match> associate(const std::vector<capture::ListLine>& color,
                             const std::vector<capture::ListLine>& depth) {
  struct Candidate {
    double diff;
    size_t color, depth;
  };
  std::vector<Candidate> candidates;
  size_t first = 0;
  for (size_t c = 0; c < color.size(); ++c) {
    const double t = color[c].timestamp;
    while (first < depth.size() && depth[first].timestamp <= t - kMaxAssociationGap) ++first;
    for (size_t d = first; d < depth.size() && depth[d].timestamp < t + kMaxAssociationGap; ++d)
      candidates.push_back({std::abs(depth[d].timestamp - t), c, d});
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.diff < b.diff; });
  std::vector<char> color_used(color.size(), 0), depth_used(depth.size(), 0);
  std::vector<Match> matches;
  for (const Candidate& c : candidates) {
    if (color_used[c.color] || depth_used[c.depth]) continue;
    color_used[c.color] = depth_used[c.depth] = 1;
    matches.push_back({c.color, c.depth});
  }
  std::sort(matches.begin(), matches.end(), [](const Match& a, const Match& b) { return a.color < b.color; });
  return matches;
}

Status check_size(const std::string& file, int w, int h, const Intrinsics& k, const char* which) {
  if (w != k.width || h != k.height)
    return fail(ErrorKind::BadInput, file + ": image is " + std::to_string(w) + "x" + std::to_string(h) +
                                         ", expected " + std::to_string(k.width) + "x" +
                                         std::to_string(k.height) + " (the " + which +
                                         " intrinsics of capture.json, or the TUM defaults)");
  return ok_status();
}

}  // namespace

Expected<CaptureReader> CaptureReader::open(const std::string& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
    return fail(ErrorKind::NotFound, folder + ": capture folder does not exist");
  CaptureReader reader;
  reader.folder_ = folder;
  const fs::path dir(folder);

  const std::string capture_json = (dir / "capture.json").string();
  auto has_capture_json = optional_file(capture_json);
  if (!has_capture_json) return has_capture_json.error();
  if (*has_capture_json) {
    auto info = load_capture_json(capture_json);
    if (!info) return info.error();
    reader.info_ = *info;
  }

  for (const char* required : {"rgb.txt", "depth.txt"}) {
    auto present = optional_file((dir / required).string());
    if (!present) return present.error();
    if (!*present)
      return fail(ErrorKind::NotFound, (dir / required).string() +
                                           ": missing; a capture folder needs rgb.txt and depth.txt "
                                           "(TUM lists 'timestamp path')");
  }
  auto color = read_image_list(folder, "rgb.txt", 1, "timestamp path");
  if (!color) return color.error();
  auto depth = read_image_list(folder, "depth.txt", 1, "timestamp path");
  if (!depth) return depth.error();
  if (color->empty())
    return fail(ErrorKind::BadInput, (dir / "rgb.txt").string() + ": lists no frames");

  const std::vector<Match> matches = associate(*color, *depth);
  if (matches.empty())
    return fail(ErrorKind::BadInput, (dir / "depth.txt").string() +
                                         ": no depth frame lies within 0.02 s of any colour frame "
                                         "of rgb.txt (TUM association rule)");
  reader.dropped_color_frames_ = color->size() - matches.size();

  std::vector<TimedPose> poses;
  const std::string gt_path = (dir / "groundtruth.txt").string();
  auto has_gt = optional_file(gt_path);
  if (!has_gt) return has_gt.error();
  if (*has_gt) {
    auto gt = read_groundtruth(gt_path);
    if (!gt) return gt.error();
    poses = std::move(*gt);
  }

  std::vector<double> env_times;
  std::vector<std::string> env_paths;
  auto has_env = optional_file((dir / "env.txt").string());
  if (!has_env) return has_env.error();
  if (*has_env) {
    auto env = read_image_list(folder, "env.txt", 1, "timestamp path");
    if (!env) return env.error();
    for (const auto& line : *env) {
      env_times.push_back(line.timestamp);
      env_paths.push_back(line.fields[0]);
    }
  }

  for (const Match& m : matches) {
    CaptureFrameEntry e;
    e.timestamp = (*color)[m.color].timestamp;
    e.rgb = (*color)[m.color].fields[0];
    e.depth = (*depth)[m.depth].fields[0];
    e.depth_timestamp = (*depth)[m.depth].timestamp;
    e.pose = pose_at(poses, e.timestamp);
    const long env = nearest_index(env_times, e.timestamp);
    if (env >= 0) e.env = env_paths[size_t(env)];
    reader.entries_.push_back(std::move(e));
  }

  const std::string ref_list = (dir / "reference.txt").string();
  auto has_refs = optional_file(ref_list);
  if (!has_refs) return has_refs.error();
  if (*has_refs) {
    auto refs = read_image_list(folder, "reference.txt", 2, "timestamp path [mask_path]");
    if (!refs) return refs.error();
    std::vector<double> all_color_times;
    for (const auto& line : *color) all_color_times.push_back(line.timestamp);
    for (const auto& line : *refs) {
      const long c = nearest_index(all_color_times, line.timestamp);
      if (std::abs(all_color_times[size_t(c)] - line.timestamp) >= kMaxAssociationGap)
        return fail(ErrorKind::BadInput, ref_list + ":" + std::to_string(line.line) +
                                             ": no colour frame of rgb.txt within 0.02 s of timestamp " +
                                             capture::format_double(line.timestamp));
      if (is_delta_reference_path(line.fields[0]) && all_color_times[size_t(c)] != line.timestamp)
        return fail(ErrorKind::BadInput, ref_list + ":" + std::to_string(line.line) + ": delta reference '" +
                                             line.fields[0] + "' needs the rgb.txt frame of exactly timestamp " +
                                             capture::format_double(line.timestamp) + " (nearest is " +
                                             capture::format_double(all_color_times[size_t(c)]) +
                                             "); a .delta.png is stored relative to it");
      for (auto& e : reader.entries_) {  // the colour frame may have been dropped (no depth)
        if (e.timestamp != all_color_times[size_t(c)]) continue;
        e.reference = line.fields[0];
        if (line.fields.size() > 1) e.reference_mask = line.fields[1];
        e.reference_line = line.line;
      }
    }
  }

  const std::string scene_json = (dir / "scene.json").string();
  auto has_scene = optional_file(scene_json);
  if (!has_scene) return has_scene.error();
  if (*has_scene) {
    auto scene = load_scene_json(scene_json);
    if (!scene) return scene.error();
    // An environment from the env camera needs that camera and its images here, or it would
    // light nothing without a word.
    if (scene->environment.present && scene->environment.from_env_camera) {
      if (!reader.info_.env_camera)
        return fail(ErrorKind::BadInput, scene_json + ": environment.from_env_camera: true needs an environment "
                                         "camera, and " + (dir / "capture.json").string() +
                                         " has no \"env_camera\" (or give environment.image)");
      if (env_paths.empty())
        return fail(ErrorKind::BadInput, scene_json + ": environment.from_env_camera: true needs environment "
                                         "camera images, and the capture has no env.txt listing them (" +
                                         (dir / "env.txt").string() + ")");
    }
    reader.scene_ = std::move(*scene);
  }

  // The first frame's images decide sizes and bit depths early; read_frame checks every later one.
  auto first = reader.read_frame(0);
  if (!first) return first.error();
  for (size_t i = 0; i < reader.entries_.size(); ++i) {
    if (reader.entries_[i].reference.empty()) continue;
    auto ref = reader.read_reference(i);
    if (!ref) return ref.error();
    if (!reader.entries_[i].reference_mask.empty()) {
      auto mask = reader.read_reference_mask(i);
      if (!mask) return mask.error();
    }
    break;
  }
  return reader;
}

bool CaptureReader::has_references() const {
  return std::any_of(entries_.begin(), entries_.end(), [](const CaptureFrameEntry& e) { return !e.reference.empty(); });
}

Expected<InputFrame> CaptureReader::read_frame(size_t i) const {
  if (i >= entries_.size())
    return fail(ErrorKind::BadUsage, folder_ + ": frame " + std::to_string(i) + " does not exist (" +
                                         std::to_string(entries_.size()) + " frames)");
  const CaptureFrameEntry& e = entries_[i];
  InputFrame frame;
  frame.index = int64_t(i);
  frame.timestamp = e.timestamp;
  frame.depth_timestamp = e.depth_timestamp;
  frame.pose = e.pose;
  auto color = load_png_rgb8(e.rgb);
  if (!color) return color.error();
  MRGI_TRY(check_size(e.rgb, color->width, color->height, info_.color, "colour"));
  auto depth = load_png_u16(e.depth);
  if (!depth) return depth.error();
  MRGI_TRY(check_size(e.depth, depth->width, depth->height, info_.depth, "depth"));
  frame.color = std::move(*color);
  frame.depth = std::move(*depth);
  if (!e.env.empty()) {
    auto env = load_hdr_image(e.env);
    if (!env) return env.error();
    frame.env = std::move(*env);
  }
  return frame;
}

Expected<ImageRGB8> CaptureReader::read_reference(size_t i) const {
  if (i >= entries_.size() || entries_[i].reference.empty())
    return fail(ErrorKind::NotFound, folder_ + ": frame " + std::to_string(i) + " has no reference image");
  const CaptureFrameEntry& e = entries_[i];
  auto img = load_png_rgb8(e.reference);
  if (!is_delta_reference_path(e.reference)) {
    if (!img) return img.error();
    MRGI_TRY(check_size(e.reference, img->width, img->height, info_.color, "colour"));
    return img;
  }
  const std::string where = (std::filesystem::path(folder_) / "reference.txt").string() + ":" +
                            std::to_string(e.reference_line) + ": delta reference: ";
  if (!img)
    return fail(img.error().kind, where + img.error().message +
                                      " (a .delta.png holds (reference - colour) mod 256 per channel as 8-bit RGB)");
  auto color = load_png_rgb8(e.rgb);
  if (!color) return fail(color.error().kind, where + "its colour frame: " + color.error().message);
  if (img->width != color->width || img->height != color->height)
    return fail(ErrorKind::BadInput, where + e.reference + " is " + std::to_string(img->width) + "x" +
                                         std::to_string(img->height) + " but its colour frame " + e.rgb + " is " +
                                         std::to_string(color->width) + "x" + std::to_string(color->height) +
                                         "; a delta must be the size of the colour frame it is relative to");
  auto reference = decode_reference_delta(*img, *color);
  if (!reference) return reference.error();
  MRGI_TRY(check_size(e.reference, reference->width, reference->height, info_.color, "colour"));
  return reference;
}

Expected<Image<uint8_t, 1>> CaptureReader::read_reference_mask(size_t i) const {
  if (i >= entries_.size() || entries_[i].reference_mask.empty())
    return fail(ErrorKind::NotFound, folder_ + ": frame " + std::to_string(i) + " has no reference mask");
  auto img = load_png_u8(entries_[i].reference_mask);
  if (!img) return img.error();
  MRGI_TRY(check_size(entries_[i].reference_mask, img->width, img->height, info_.color, "colour"));
  return img;
}

}  // namespace mrgi
