// Picking quality: a technique's ladder (technique_ladder: each level's knobs with units), then
// a frame budget the scheduler holds (RuntimeSettings::level = kAutoLevel, frame_budget_ms), a
// budget changed at run time (Runtime::set_frame_budget_ms: a game menu's 60/30 fps switch, a
// device getting hot), and a level pinned by hand (Runtime::set_level). Prints per frame the
// level and internal resolution the runtime chose, the frame's cost and what was predicted.
// The frames are made up as in frames_from_memory (a floor under a camera looking down, a lamp).
//
//   level_and_budget OBJECT.gltf [TECHNIQUE]
//
// Exit 0 when the scheduler ran the best level under a loose budget, dropped to cheaper quality
// under a budget no level can meet, and the pinned level held.
#include <cstdio>
#include <string>
#include <vector>

#include <mrgi/runtime.h>

namespace {

mrgi::InputFrame make_frame(int64_t index, const mrgi::Intrinsics& k, double depth_scale) {
  mrgi::InputFrame f;
  f.index = index;
  f.timestamp = double(index) / 30.0;
  f.depth_timestamp = f.timestamp;
  f.color = mrgi::ImageRGB8(k.width, k.height);
  f.depth = mrgi::ImageU16(k.width, k.height);
  for (int y = 0; y < k.height; ++y)
    for (int x = 0; x < k.width; ++x) {
      f.depth.at(x, y)[0] = uint16_t(1.0 * depth_scale);
      for (int c = 0; c < 3; ++c) f.color.at(x, y)[c] = 150;
    }
  mrgi::Pose pose;
  pose.translation = {0.0, 1.0, 0.0};
  pose.rotation = glm::dquat(glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1), glm::dvec3(0, -1, 0)));
  f.pose = pose;
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3 || std::string(argv[1]) == "--help") {
    std::fprintf(stderr, "usage: %s OBJECT.gltf [TECHNIQUE]\n", argv[0]);
    return 2;
  }
  const std::string technique = argc == 3 ? argv[2] : "baseline";

  // 1. The ladder: what each level sets, with units.
  auto ladder = mrgi::technique_ladder(technique);
  if (!ladder) {
    std::fprintf(stderr, "error: %s\n", ladder.error().message.c_str());
    return 2;
  }
  std::printf("%s has %zu levels, best first:\n", technique.c_str(), ladder->size());
  for (size_t i = 0; i < ladder->size(); ++i) {
    const mrgi::QualityLevelInfo& l = (*ladder)[i];
    std::printf("  %zu %-8s internal scale %.2f", i, l.name.c_str(), l.internal_scale);
    for (size_t k = 0; k < l.knobs.size() && k < 2; ++k)
      std::printf(", %s %g (%s)", l.knobs[k].name.c_str(), l.knobs[k].value, l.knobs[k].unit.c_str());
    std::printf("\n");
  }

  // 2. A budget instead of a level: the scheduler chooses every frame.
  mrgi::SceneDesc scene;
  mrgi::VirtualObjectDesc object;
  object.gltf = argv[1];
  object.placement.scale = glm::vec3(1.5f);
  object.placement.rotation = glm::quat(0.70710678f, 0.70710678f, 0.0f, 0.0f);
  scene.virtual_objects.push_back(object);
  mrgi::LightDesc lamp;
  lamp.position = {0.4f, 1.2f, 0.3f};
  scene.lights.push_back(lamp);
  mrgi::CameraSetup cameras;
  cameras.color = cameras.depth = mrgi::Intrinsics{320, 240, 260.0, 260.0, 159.5, 119.5};
  mrgi::RuntimeSettings settings;
  settings.technique = technique;
  settings.level = mrgi::kAutoLevel;
  settings.frame_budget_ms = 500.0;  // loose: the best level fits
  auto runtime = mrgi::create_runtime(settings, cameras, scene);
  if (!runtime) {
    std::fprintf(stderr, "error: %s\n", runtime.error().message.c_str());
    return 1;
  }
  mrgi::Runtime& rt = **runtime;
  std::vector<int> levels;
  auto report = [&](std::vector<mrgi::FrameOutput>& outs) {
    for (mrgi::FrameOutput& out : outs) {
      const mrgi::FrameStats& s = out.stats;
      std::printf("frame %2lld: level %d (%s) at %.2f of the output's side, cost %.1f ms, predicted %.1f, budget %.0f\n",
                  static_cast<long long>(s.frame_index), s.level, s.scheduled ? "scheduled" : "fixed",
                  s.internal_scale, s.cost_ms, s.predicted_ms, s.budget_ms);
      levels.push_back(s.level);
      rt.recycle(std::move(out));
    }
  };
  auto run = [&](int64_t from, int64_t to) {
    for (int64_t i = from; i < to; ++i) {
      auto outs = rt.process(make_frame(i, cameras.color, cameras.depth_scale));
      if (!outs) {
        std::fprintf(stderr, "error: %s\n", outs.error().message.c_str());
        return false;
      }
      report(*outs);
    }
    return true;
  };
  if (!run(0, 10)) return 1;
  // 3. The budget changes at run time: 1 ms, which no level meets; the scheduler drops level
  //    after a few frames over it (it never allocates doing so).
  if (auto s = rt.set_frame_budget_ms(1.0); !s) return 1;
  if (!run(10, 40)) return 1;
  // 4. A level pinned by hand: the scheduler stops choosing until set_level(kAutoLevel).
  if (auto s = rt.set_level(1); !s) return 1;
  if (!run(40, 46)) return 1;
  auto rest = rt.flush();
  if (!rest) return 1;
  report(*rest);
  const int last = int(ladder->size()) - 1;
  const bool best_when_loose = levels.size() == 46 && levels[5] == 0;
  const bool cheaper_when_tight = levels.size() == 46 && levels[38] == last;
  const bool pinned = levels.size() == 46 && levels[45] == 1;
  std::printf("loose budget ran the best level: %s; an impossible one dropped to the cheapest: %s; pinned level held: %s\n",
              best_when_loose ? "yes" : "no", cheaper_when_tight ? "yes" : "no", pinned ? "yes" : "no");
  return best_when_loose && cheaper_when_tight && pinned ? 0 : 1;
}
