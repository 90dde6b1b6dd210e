// What `mrgi synth --resume` needs to continue an interrupted render: OUT.partial/synth_resume.json
// holds a fingerprint of everything the output depends on (the description file and the files it
// names, and the effective settings) and, per finished frame, what the report sums up (dropped
// samples, frame 0's noise floor). The frames themselves are CaptureWriter's (writer_progress.json).
// A record is saved before its frame is handed to the writer, so the records always cover the
// writer's frames; records past them (a frame cut off half-way) are dropped on resume.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/reference/synth.h"

namespace mrgi::reference {

inline constexpr const char* kSynthResumeFile = "synth_resume.json";

struct SynthFrameRecord {
  size_t dropped_samples = 0;
  double seconds = 0.0;  // wall time rendering the frame (frame 0: with the noise-floor render)
  std::optional<NoiseFloor> noise_floor;
};

struct SynthResumeState {
  std::string fingerprint;   // 16 hex digits
  std::string settings;      // the settings in words, for messages
  std::vector<SynthFrameRecord> frames;
};

// Fingerprint and settings text of description D (already with the options' overrides applied)
// rendered with OPTIONS. The render threads are left out: they do not change the output. The
// renderer's own code is not part of it (a rebuilt mrgi may resume).
Expected<SynthResumeState> synth_resume_identity(const SceneDescription& d, const SynthOptions& options);

Expected<SynthResumeState> load_synth_resume(const std::string& path);
Status save_synth_resume(const std::string& path, const SynthResumeState& state);

}  // namespace mrgi::reference
