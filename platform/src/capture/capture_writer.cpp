// Capture format v1 writer. Frames go to FOLDER.partial/{rgb,depth,env,reference}/NNNNNN.*, the
// lists and JSON files are written by finish(), and only then is FOLDER.partial renamed to
// FOLDER. Timestamps and poses are written in shortest round-trip decimal, so a reader gets back
// bit-identical values. Env images are stored as 32-bit float OpenEXR, an image equal to the
// last one written (a static environment camera) once: env.txt lists its file again. References are stored plain
// or as deltas from the colour frame (ReferenceStorage, mrgi/platform/capture_references.h). After
// every frame the lists so far go to FOLDER.partial/writer_progress.json, so resume() can continue
// a write that was cut off (long path-traced renders).
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "mrgi/platform/output_dir.h"
#include "capture/capture_text.h"
#include "mrgi/platform/capture.h"
#include "mrgi/platform/capture_references.h"

namespace mrgi {
namespace {

namespace fs = std::filesystem;

// Written into FOLDER.partial after every frame so resume() can continue; finish() removes it.
constexpr const char* kProgressFile = "writer_progress.json";

const char* storage_name(ReferenceStorage s) { return s == ReferenceStorage::Delta ? "delta" : "plain"; }

std::string normalized_folder(const std::string& folder) {
  std::string f = fs::path(folder).lexically_normal().string();
  while (!f.empty() && f.back() == '/' && f.size() > 1) f.pop_back();
  return f;
}

std::string frame_name(size_t index, const char* suffix) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%06zu%s", index, suffix);
  return buf;
}

std::string list_header(const char* what, const char* format) {
  return std::string("# ") + what + " (mrgi capture format v1)\n# " + format + "\n";
}

Status check_image_size(const std::string& folder, const char* what, int w, int h, const Intrinsics& k) {
  if (w != k.width || h != k.height)
    return fail(ErrorKind::BadUsage, folder + ": " + what + " image is " + std::to_string(w) + "x" +
                                         std::to_string(h) + ", but the capture's intrinsics say " +
                                         std::to_string(k.width) + "x" + std::to_string(k.height));
  return ok_status();
}

}  // namespace

Expected<CaptureWriter> CaptureWriter::create(const std::string& folder, const CaptureInfo& info,
                                              const std::optional<SceneDesc>& scene,
                                              ReferenceStorage references) {
  std::error_code ec;
  if (fs::exists(folder, ec) && !(fs::is_directory(folder, ec) && fs::is_empty(folder, ec)))
    return fail(ErrorKind::BadUsage, folder + ": already exists and is not an empty folder; remove it "
                                              "first (a capture is never written over another)");
  CaptureWriter w;
  w.folder_ = normalized_folder(folder);
  w.partial_ = w.folder_ + ".partial";
  w.info_ = info;
  w.reference_storage_ = references;
  // A left-over .partial is replaced only when an mrgi writer made it (its marker file; user
  // data under that name is refused, untouched). The marker is written first into the new one.
  if (fs::exists(fs::symlink_status(w.partial_, ec)) && !is_replaceable_output(w.partial_))
    return fail(ErrorKind::BadUsage, w.partial_ + ": exists and was not written by mrgi (no " +
                                         std::string(OutputDir::kMarker) +
                                         " marker in it); refusing to replace it: remove it yourself");
  fs::remove_all(w.partial_, ec);
  fs::create_directories(w.partial_, ec);
  std::ofstream(fs::path(w.partial_) / OutputDir::kMarker)
      << "Written by mrgi: an unfinished capture, which a later run may replace.\n";
  for (const char* sub : {"rgb", "depth"}) {
    fs::create_directories(fs::path(w.partial_) / sub, ec);
    if (ec)
      return fail(ErrorKind::Device, w.partial_ + ": cannot create folder '" + sub + "': " + ec.message());
  }
  if (scene) {
    // Written now so its paths are made relative to the folder's final parent (FOLDER.partial is
    // FOLDER's sibling, so relative paths stay valid after the rename).
    MRGI_TRY(write_scene_json((fs::path(w.partial_) / "scene.json").string(), *scene));
  }
  w.rgb_list_ = list_header("colour images", "timestamp filename");
  w.depth_list_ = list_header("depth images", "timestamp filename");
  w.gt_list_.clear();
  w.env_list_.clear();
  w.ref_list_.clear();
  return w;
}

Expected<CaptureWriter> CaptureWriter::resume(const std::string& folder, const CaptureInfo& info,
                                              const std::optional<SceneDesc>& scene,
                                              ReferenceStorage references) {
  std::error_code ec;
  if (fs::exists(folder, ec) && !(fs::is_directory(folder, ec) && fs::is_empty(folder, ec)))
    return fail(ErrorKind::BadUsage, folder + ": already exists and is not an empty folder; a finished "
                                              "capture is not resumed");
  CaptureWriter w;
  w.folder_ = normalized_folder(folder);
  w.partial_ = w.folder_ + ".partial";
  w.info_ = info;
  w.reference_storage_ = references;
  if (!fs::is_directory(w.partial_, ec))
    return fail(ErrorKind::NotFound, w.partial_ + ": does not exist; there is no interrupted write to resume");
  const std::string progress = (fs::path(w.partial_) / kProgressFile).string();
  std::ifstream in(progress, std::ios::binary);
  if (!in)
    return fail(ErrorKind::NotFound, progress + ": missing; " + w.partial_ +
                                         " holds no finished frame of an interrupted write (remove it and start again)");
  std::stringstream text;
  text << in.rdbuf();
  try {
    const nlohmann::json j = nlohmann::json::parse(text.str());
    if (j.at("version").get<int>() != 1)
      return fail(ErrorKind::BadInput, progress + ": version must be 1");
    const std::string stored = j.at("reference_storage").get<std::string>();
    if (stored != storage_name(references))
      return fail(ErrorKind::BadUsage, progress + ": reference_storage: the write started with " + stored +
                                           " references and cannot go on with " + storage_name(references) + " ones");
    w.count_ = j.at("frames").get<size_t>();
    const std::string last = j.at("last_timestamp").get<std::string>();
    if (!capture::parse_double(last, &w.last_timestamp_))
      return fail(ErrorKind::BadInput, progress + ": last_timestamp '" + last + "' is not a finite number");
    const nlohmann::json& lists = j.at("lists");
    w.rgb_list_ = lists.at("rgb").get<std::string>();
    w.depth_list_ = lists.at("depth").get<std::string>();
    w.gt_list_ = lists.at("groundtruth").get<std::string>();
    w.env_list_ = lists.at("env").get<std::string>();
    w.ref_list_ = lists.at("reference").get<std::string>();
  } catch (const nlohmann::json::exception& e) {
    return fail(ErrorKind::BadInput, progress + ": " + e.what());
  }
  if (scene) MRGI_TRY(write_scene_json((fs::path(w.partial_) / "scene.json").string(), *scene));
  return w;
}

Status CaptureWriter::save_progress() const {
  nlohmann::json j;
  j["version"] = 1;
  j["frames"] = count_;
  j["last_timestamp"] = capture::format_double(last_timestamp_);
  j["reference_storage"] = storage_name(reference_storage_);
  j["lists"] = {{"rgb", rgb_list_}, {"depth", depth_list_}, {"groundtruth", gt_list_}, {"env", env_list_},
                {"reference", ref_list_}};
  return capture::write_text((fs::path(partial_) / kProgressFile).string(), j.dump(2) + "\n");
}

Status CaptureWriter::add_frame(const InputFrame& frame, const ImageRGB8* reference,
                                const Image<uint8_t, 1>* reference_mask) {
  if (partial_.empty()) return fail(ErrorKind::BadUsage, folder_ + ": writer already finished");
  MRGI_TRY(check_image_size(folder_, "colour", frame.color.width, frame.color.height, info_.color));
  MRGI_TRY(check_image_size(folder_, "depth", frame.depth.width, frame.depth.height, info_.depth));
  if (!std::isfinite(frame.timestamp) || !std::isfinite(frame.depth_timestamp))
    return fail(ErrorKind::BadUsage, folder_ + ": frame " + std::to_string(count_) + ": timestamps must be finite");
  if (count_ > 0 && !(frame.timestamp > last_timestamp_))
    return fail(ErrorKind::BadUsage, folder_ + ": frame " + std::to_string(count_) + ": timestamp " +
                                         capture::format_double(frame.timestamp) +
                                         " does not increase (previous " +
                                         capture::format_double(last_timestamp_) + ")");
  if (std::abs(frame.depth_timestamp - frame.timestamp) >= 0.02)
    return fail(ErrorKind::BadUsage, folder_ + ": frame " + std::to_string(count_) +
                                         ": depth timestamp is 0.02 s or more from the colour "
                                         "timestamp; a reader would not associate them");
  const bool has_pose = frame.pose.has_value();
  if (count_ > 0 && has_pose != !gt_list_.empty())
    return fail(ErrorKind::BadUsage, folder_ + ": frame " + std::to_string(count_) +
                                         ": either every frame has a pose or none has");
  if (has_pose) {
    const Pose& p = *frame.pose;
    const double len = std::sqrt(glm::dot(p.rotation, p.rotation));
    if (!std::isfinite(len) || !std::isfinite(glm::dot(p.translation, p.translation)) ||
        std::abs(len - 1.0) > 1e-3)
      return fail(ErrorKind::BadUsage, folder_ + ": frame " + std::to_string(count_) +
                                           ": pose must be finite with a unit quaternion (within 0.001)");
  }
  if (reference_mask && !reference)
    return fail(ErrorKind::BadUsage, folder_ + ": a reference mask needs a reference image");
  if (reference) {
    MRGI_TRY(check_image_size(folder_, "reference", reference->width, reference->height, info_.color));
  }
  if (reference_mask)
    MRGI_TRY(check_image_size(folder_, "reference mask", reference_mask->width, reference_mask->height,
                              info_.color));

  const fs::path dir(partial_);
  const std::string ts = capture::format_double(frame.timestamp);
  const std::string rgb = "rgb/" + frame_name(count_, ".png");
  const std::string depth = "depth/" + frame_name(count_, ".png");
  MRGI_TRY(write_png((dir / rgb).string(), frame.color, png_effort_));
  MRGI_TRY(write_png((dir / depth).string(), frame.depth, png_effort_));
  rgb_list_ += ts + " " + rgb + "\n";
  depth_list_ += capture::format_double(frame.depth_timestamp) + " " + depth + "\n";
  if (has_pose) {
    if (gt_list_.empty()) gt_list_ = list_header("ground-truth camera-to-world poses", "timestamp tx ty tz qx qy qz qw");
    const Pose& p = *frame.pose;
    gt_list_ += ts;
    for (double v : {p.translation.x, p.translation.y, p.translation.z, p.rotation.x, p.rotation.y,
                     p.rotation.z, p.rotation.w})
      gt_list_ += " " + capture::format_double(v);
    gt_list_ += "\n";
  }
  if (frame.env) {
    const ImageRGBF& e = *frame.env;
    const bool unchanged = !last_env_path_.empty() && e.width == last_env_.width && e.height == last_env_.height &&
                           e.data.size() == last_env_.data.size() &&
                           std::memcmp(e.data.data(), last_env_.data.data(), e.data.size() * sizeof(float)) == 0;
    std::string env = last_env_path_;
    if (!unchanged) {
      std::error_code ec;
      fs::create_directories(dir / "env", ec);
      env = "env/" + frame_name(count_, ".exr");
      MRGI_TRY(write_exr((dir / env).string(), e));
      last_env_ = e;
      last_env_path_ = env;
    }
    if (env_list_.empty()) env_list_ = list_header("environment images (linear radiance)", "timestamp filename");
    env_list_ += ts + " " + env + "\n";
  }
  if (reference) {
    std::error_code ec;
    fs::create_directories(dir / "reference", ec);
    if (ref_list_.empty()) ref_list_ = list_header("ground-truth augmented frames", "timestamp filename [mask_filename]");
    const bool delta = reference_storage_ == ReferenceStorage::Delta;
    const std::string ref = "reference/" + frame_name(count_, delta ? kDeltaReferenceSuffix : ".png");
    if (delta) {
      // Same size as the colour frame: both were checked against the intrinsics above.
      auto stored = encode_reference_delta(*reference, frame.color);
      if (!stored) return stored.error();
      MRGI_TRY(write_png((dir / ref).string(), *stored, png_effort_));
    } else {
      MRGI_TRY(write_png((dir / ref).string(), *reference, png_effort_));
    }
    ref_list_ += ts + " " + ref;
    if (reference_mask) {
      const std::string mask = "reference/" + frame_name(count_, "_mask.png");
      MRGI_TRY(write_png((dir / mask).string(), *reference_mask, png_effort_));
      ref_list_ += " " + mask;
    }
    ref_list_ += "\n";
  }
  last_timestamp_ = frame.timestamp;
  ++count_;
  return save_progress();
}

Status CaptureWriter::finish() {
  if (partial_.empty()) return fail(ErrorKind::BadUsage, folder_ + ": writer already finished");
  if (count_ == 0) return fail(ErrorKind::BadUsage, folder_ + ": no frames were added");
  const fs::path dir(partial_);
  MRGI_TRY(capture::write_text((dir / "rgb.txt").string(), rgb_list_));
  MRGI_TRY(capture::write_text((dir / "depth.txt").string(), depth_list_));
  if (!gt_list_.empty()) MRGI_TRY(capture::write_text((dir / "groundtruth.txt").string(), gt_list_));
  if (!env_list_.empty()) MRGI_TRY(capture::write_text((dir / "env.txt").string(), env_list_));
  if (!ref_list_.empty()) MRGI_TRY(capture::write_text((dir / "reference.txt").string(), ref_list_));
  MRGI_TRY(write_capture_json((dir / "capture.json").string(), info_));
  std::error_code ec;
  fs::remove(dir / kProgressFile, ec);
  if (ec) return fail(ErrorKind::Device, (dir / kProgressFile).string() + ": cannot remove: " + ec.message());
  // A finished capture is data, not an output a later run may replace: the marker goes.
  fs::remove(dir / OutputDir::kMarker, ec);
  ec.clear();
  if (fs::exists(folder_, ec)) {
    if (!fs::is_empty(folder_, ec))
      return fail(ErrorKind::BadUsage, folder_ + ": appeared and is not empty while the capture was "
                                                 "written; the capture stays in " + partial_);
    fs::remove(folder_, ec);
  }
  fs::rename(partial_, folder_, ec);
  if (ec) return fail(ErrorKind::Device, folder_ + ": cannot rename " + partial_ + ": " + ec.message());
  partial_.clear();
  return ok_status();
}

}  // namespace mrgi
