/// \file
/// Capture format v1 (docs/DESIGN.md): a TUM RGB-D compatible folder.
/// <pre>
///   rgb.txt, depth.txt       "timestamp path" per line, '#' comments
///   rgb/*.png                8-bit sRGB colour      depth/*.png  16-bit, depth_scale units per metre
///   groundtruth.txt          optional "timestamp tx ty tz qx qy qz qw", camera-to-world
///   env.txt, env/*           optional environment images (.hdr, .exr, .png)
///   capture.json             optional intrinsics, depth_scale, exposure, env camera, AprilTag
///   scene.json               optional (mrgi/scene.h)
///   reference.txt, reference/*  optional ground-truth augmented frames (8-bit sRGB PNG):
///                            "timestamp path [mask_path]"; the optional mask is 8-bit grey,
///                            non-zero where a virtual object is seen (for RDE over virtual pixels).
///                            A reference named *.delta.png is stored as (reference - colour) mod 256
///                            per channel, 8-bit RGB, relative to the rgb.txt frame with exactly the
///                            same timestamp (lossless; most pixels equal the colour frame, so it
///                            compresses far better); read_reference returns the reconstructed frame.
/// </pre>
/// Colour and depth are associated by nearest timestamp (TUM associate.py rule, max 0.02 s);
/// poses are interpolated (slerp) at the colour timestamp.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/export.h"
#include "mrgi/frame.h"
#include "mrgi/scene.h"

namespace mrgi {

struct TagPose {
  int id = 0;
  Pose tag_to_world;
};

struct AprilTagSettings {
  std::string family = "tag36h11";
  double size_m = 0.1;           ///< black square edge length, metres
  std::vector<TagPose> tags;     ///< known tag poses in the world
};

/// capture.json v1. Defaults are TUM Freiburg 1 (what applies when the file is absent).
struct CaptureInfo {
  int version = 1;
  Intrinsics color;               ///< colour camera
  Intrinsics depth;               ///< depth camera (registered to colour when equal)
  double depth_scale = 5000.0;    ///< depth units per metre (TUM: 5000)
  double exposure = 1.0;          ///< linear radiance -> linear camera value, before the sRGB curve
  std::optional<EnvCamera> env_camera;
  std::optional<AprilTagSettings> apriltag;
};

struct CaptureFrameEntry {
  double timestamp = 0.0;
  std::string rgb;                ///< absolute paths
  std::string depth;
  double depth_timestamp = 0.0;
  std::optional<Pose> pose;
  std::string env;                ///< empty when none
  std::string reference;          ///< empty when none
  std::string reference_mask;     ///< empty when none
  int reference_line = 0;         ///< line of reference.txt that lists them (for messages)
};

class MRGI_API CaptureReader {
 public:
  /// Validates the folder's lists, capture.json, scene.json and every file's existence, and the
  /// first frame's image sizes and bit depths. Errors name file, line and rule.
  static Expected<CaptureReader> open(const std::string& folder);

  const std::string& folder() const { return folder_; }
  const CaptureInfo& info() const { return info_; }
  const std::optional<SceneDesc>& scene() const { return scene_; }
  size_t frame_count() const { return entries_.size(); }
  const CaptureFrameEntry& entry(size_t i) const { return entries_[i]; }
  bool has_references() const;
  /// Colour frames of rgb.txt left out because no depth frame lay within 0.02 s of them.
  size_t dropped_color_frames() const { return dropped_color_frames_; }

  /// Loads frame i, checking image sizes against the intrinsics and bit depths (8-bit RGB colour,
  /// 16-bit single-channel depth).
  Expected<InputFrame> read_frame(size_t i) const;
  Expected<ImageRGB8> read_reference(size_t i) const;
  Expected<Image<uint8_t, 1>> read_reference_mask(size_t i) const;  ///< NotFound when absent

 private:
  std::string folder_;
  CaptureInfo info_;
  std::optional<SceneDesc> scene_;
  std::vector<CaptureFrameEntry> entries_;
  size_t dropped_color_frames_ = 0;
};

/// How CaptureWriter stores reference frames: Plain as reference/NNNNNN.png, Delta as
/// reference/NNNNNN.delta.png (see the header comment; mrgi/platform/capture_references.h).
enum class ReferenceStorage { Plain, Delta };

/// Writes a capture folder. The folder is built under FOLDER.partial and renamed on finish(),
/// so an interrupted write never leaves something that looks like a valid capture.
class MRGI_API CaptureWriter {
 public:
  static Expected<CaptureWriter> create(const std::string& folder, const CaptureInfo& info,
                                        const std::optional<SceneDesc>& scene,
                                        ReferenceStorage references = ReferenceStorage::Plain);
  /// Continues a write that was cut off (process killed, or the writer dropped before finish()):
  /// FOLDER.partial must hold the progress file add_frame writes after every frame
  /// (writer_progress.json; finish() removes it), written with the same REFERENCES storage. Its
  /// frames are kept; files of a frame cut off half-way are overwritten by the next add_frame.
  /// The caller vouches that INFO and SCENE are those the write started with.
  static Expected<CaptureWriter> resume(const std::string& folder, const CaptureInfo& info,
                                        const std::optional<SceneDesc>& scene,
                                        ReferenceStorage references = ReferenceStorage::Plain);
  Status add_frame(const InputFrame& frame, const ImageRGB8* reference = nullptr,
                   const Image<uint8_t, 1>* reference_mask = nullptr);
  Status finish();
  size_t frame_count() const { return count_; }  ///< frames added so far (resumed ones included)
  /// PNG effort for the frames written from now on (default Fast, for live recording; synth and
  /// reference conversion use Small because their output is stored in the repository).
  void set_png_effort(PngEffort effort) { png_effort_ = effort; }

 private:
  Status save_progress() const;

  std::string folder_, partial_;
  CaptureInfo info_;
  ReferenceStorage reference_storage_ = ReferenceStorage::Plain;
  PngEffort png_effort_ = PngEffort::Fast;
  std::string rgb_list_, depth_list_, gt_list_, env_list_, ref_list_;
  // The last environment image written and its file: an unchanged one (a static environment
  // camera) is listed again for the frame, not stored again.
  ImageRGBF last_env_;
  std::string last_env_path_;
  size_t count_ = 0;
  double last_timestamp_ = 0.0;
};

MRGI_API Expected<CaptureInfo> load_capture_json(const std::string& path);
MRGI_API Status write_capture_json(const std::string& path, const CaptureInfo& info);

}  // namespace mrgi
