// The live view's requests applied to a runtime (live_view.h), shared by replay and live.
#include <algorithm>
#include <cstdio>

#include "commands.h"
#include "live_view.h"

namespace mrgi::tool {

std::string view_status(const Runtime& runtime, const FrameStats& stats) {
  const std::vector<std::string> levels = runtime.level_names();
  const std::string level =
      stats.level >= 0 && size_t(stats.level) < levels.size() ? levels[size_t(stats.level)] : "?";
  char text[200];
  std::snprintf(text, sizeof text, "frame %lld  %s %s%s  scale %.2f  cost %.1f ms", static_cast<long long>(stats.frame_index),
                runtime.technique().c_str(), level.c_str(), stats.scheduled ? " (auto)" : "",
                double(stats.internal_scale), stats.cost_ms);
  return text;
}

Status step_level(Runtime& runtime, const FrameStats& stats, int step) {
  if (step == 0) return ok_status();
  const int last = int(runtime.level_names().size()) - 1;
  return runtime.set_level(std::clamp(stats.level + step, 0, last));
}

Expected<RuntimeSettings> next_technique_settings(const RuntimeSettings& current, const std::string& technique) {
  const std::vector<std::string> names = technique_names();
  if (names.empty()) return fail(ErrorKind::Internal, "view: no technique registered");
  const auto at = std::find(names.begin(), names.end(), technique);
  RuntimeSettings next = current;
  next.technique = names[at == names.end() ? 0 : size_t(at + 1 - names.begin()) % names.size()];
  next.knobs.clear();
  auto levels = technique_levels(next.technique);
  if (!levels) return levels.error();
  if (next.level != kAutoLevel) next.level = std::min(next.level, int(levels->size()) - 1);
  return next;
}

void ViewOptions::add(CLI::App& cmd, const std::string& frames, const std::string& end) {
  cmd.add_flag("--view", view,
               "show each composite in a window " + frames +
                   " (the window's own Vulkan device, mrgi running on it). Keys: T next technique, [ ] a cheaper / "
                   "better level, S the camera frame beside it, I the frame's figures in the title, Space pause, Q "
                   "or Esc quit. Needs a display ($DISPLAY; xvfb-run without one)");
  cmd.add_option("--view-screenshot", screenshot,
                 "with --view: " + end +
                     ", write the window's pixels as the X server holds them to FILE (PNG) and close, instead of "
                     "keeping the window up");
}

}  // namespace mrgi::tool
