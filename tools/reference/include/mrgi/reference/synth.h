// The synthetic capture generator behind `mrgi synth`: renders a scene description
// (mrgi/reference/description.h) with the reference path tracer and its sensor models and
// writes a capture v1 folder (docs/DESIGN.md) through CaptureWriter:
//   rgb/, depth/, groundtruth.txt   camera frames C (camera response of L_r, sensor noise), Kinect
//                                   depth of the real scene, camera-to-world poses
//   env/                            fisheye HDR frames (.exr) when the description has an env camera
//   reference/                      G = camera response of L_rv with the same noise realisation,
//                                   stored as *.delta.png (G - C mod 256, lossless, much smaller)
//                                   or plain *.png (SynthOptions::references), and *_mask.png
//                                   (255 where the pixel-centre ray sees a virtual object)
//   capture.json                    intrinsics, depth_scale, exposure, env camera model and pose
//   scene.json                      virtual objects (glTF copied under virtual/, frame-0 placement),
//                                   lamps with their `real` flags (area lamps cannot be listed),
//                                   environment from the env camera or a downsampled copy under
//                                   environment/; no real_geometry (the runtime reconstructs it)
// The output is a pure function of the description and the options: two runs give identical files,
// also when one of them was interrupted and resumed (SynthOptions::resume).
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/platform/capture.h"
#include "mrgi/reference/description.h"

namespace mrgi::reference {

struct SynthOptions {
  std::string out;                      // capture folder to create (must not exist yet)
  std::optional<int> frames, spp, width, height;  // overrides of the description
  std::optional<uint64_t> seed;
  int threads = 0;                      // 0 = hardware concurrency
  // When set, frame 0 is rendered a second time with this seed (in memory only) to measure the
  // reference noise floor (SynthReport::noise_floor).
  std::optional<uint64_t> noise_floor_seed;
  // How references are stored: Delta (default; mrgi/platform/capture_references.h) or Plain PNG.
  ReferenceStorage references = ReferenceStorage::Delta;
  // Continue an interrupted render: the frames already finished in OUT.partial are kept and only
  // the missing ones are rendered; OUT.partial must have been started from the same description,
  // input files and settings (fingerprint in OUT.partial/synth_resume.json), else BadUsage. With
  // no OUT.partial the render starts from frame 0. The result is bit-identical to one
  // uninterrupted render.
  bool resume = false;
  // Render at most this many frames in this run, then stop and leave OUT.partial for `resume`
  // (splits a long render over several runs). Unset: render to the end.
  std::optional<int> stop_after;
  // When set, the frames are not path-traced: their radiance, depth, normals, virtual masks and
  // env images are read from this folder of another renderer's images of the same description
  // (tools/cycles/render_description.py; layout in synth_from_renders.h), and go through the same
  // sensor models and capture writer. No light probe is made. Not with noise_floor_seed, resume
  // or stop_after (a conversion is quick: run it again).
  std::string from_renders;
  // Progress over all frames: (what, done, total, seconds elapsed).
  std::function<void(const std::string&, size_t, size_t, double)> progress;
};

// How far the reference is from converged: the RDE a perfect system would score against this
// capture's frame 0 if its answer came from an independent render (another seed B):
//   RDE = ||(G_B - C_B) - (G_A - C_A)|| / ||G_A - C_A||, linear RGB decoded from the 8-bit frames,
// over all pixels, real pixels (mask 0) and virtual pixels (mask non-zero). 0 = converged.
struct NoiseFloor {
  double rde_all = 0.0, rde_real = 0.0, rde_virtual = 0.0;
  double delta_rms = 0.0;  // RMS of ||G_A - C_A|| per pixel, linear: how large the effect is
};

struct SynthReport {
  int frames = 0;
  int spp = 0;
  int frames_resumed = 0;    // kept from an interrupted render (SynthOptions::resume)
  int frames_rendered = 0;   // rendered by this run
  bool finished = true;      // false: stopped by stop_after; OUT.partial awaits resume
  double seconds = 0.0;      // this run's wall time
  double frame_seconds = 0.0;  // wall time rendering the frames done so far, over all runs
  size_t dropped_samples = 0;
  std::optional<NoiseFloor> noise_floor;
};

Expected<SynthReport> synthesize_capture(const SceneDescription& description, const SynthOptions& options);

}  // namespace mrgi::reference
