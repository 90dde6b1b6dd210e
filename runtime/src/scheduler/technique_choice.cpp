// --technique auto: which technique a scene runs (mrgi/runtime.h choose_technique).
#include <algorithm>
#include <cstdio>
#include <limits>

#include "mrgi/runtime.h"
#include "mrgi/scene.h"
#include "frame/scene_gpu.h"

namespace mrgi {
namespace {

// Suite aggregate of `mrgi bench -t baseline,ssrt,dlpv,dir -l all -s desk_spot,corner -n 6` on
// lavapipe with 2 threads at 640x480 (perf/results/scheduler/README.md "Priors"): sustained ms
// (geometric mean over the two scenes) and RDE over all pixels (mean).
const std::vector<TechniqueFigure>& builtin_table() {
  static const std::vector<TechniqueFigure> table = {
      {"baseline", 0, 206.9, 0.254}, {"baseline", 1, 124.5, 0.260}, {"baseline", 2, 76.2, 0.359},
      {"baseline", 3, 26.8, 0.389},  {"ssrt", 0, 1215.1, 0.811},    {"ssrt", 1, 676.5, 0.778},
      {"ssrt", 2, 42.7, 0.800},      {"ssrt", 3, 31.3, 0.843},      {"dlpv", 0, 468.1, 0.488},
      {"dlpv", 1, 611.8, 0.372},     {"dlpv", 2, 178.3, 0.287},     {"dlpv", 3, 41.0, 0.385},
      {"dlpv", 4, 41.3, 0.384},      {"dir", 0, 909.1, 0.198},      {"dir", 1, 672.5, 0.204},
      {"dir", 2, 244.2, 0.222},      {"dir", 3, 38.2, 0.390},       {"dir", 4, 52.7, 0.388},
  };
  return table;
}

std::string fmt(double v, int decimals) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

}  // namespace

Expected<TechniqueChoice> choose_technique(const SceneDesc& scene, double budget_ms,
                                           const std::vector<TechniqueFigure>& table_in, double headroom,
                                           bool glossy_objects_added) {
  if (!(budget_ms > 0.0)) return fail(ErrorKind::BadUsage, "choose_technique: the budget must be > 0 ms");
  const std::vector<TechniqueFigure>& table = table_in.empty() ? builtin_table() : table_in;
  bool glossy = false;
  for (const VirtualObjectDesc& o : scene.virtual_objects) {
    auto model = load_gltf(o.gltf, o.placement);
    if (!model) return model.error();
    for (const Material& m : model->materials)
      glossy = glossy || m.metallic > frame::SceneGpu::kGlossyMetallic ||
               m.roughness < frame::SceneGpu::kGlossyRoughness;
  }
  const bool lamp = !scene.lights.empty();
  std::string reason;
  std::vector<std::string> candidates;
  for (const std::string& t : technique_names()) {
    if (!lamp && (t == "dlpv" || t == "dir")) {
      reason += t + " left out: no lamp (its bounce starts at the lamps' reflective shadow maps); ";
      continue;
    }
    if ((glossy || glossy_objects_added) && t == "ssrt") {
      reason += t + (glossy ? " left out: a glossy virtual material (its transfer is diffuse); "
                            : " left out: room for glossy objects added at run time (its transfer is diffuse); ");
      continue;
    }
    candidates.push_back(t);
  }
  const double target = budget_ms * (1.0 - headroom);
  std::string best, fastest;
  double best_rde = std::numeric_limits<double>::infinity(), fastest_ms = std::numeric_limits<double>::infinity();
  int best_level = -1;
  for (const std::string& t : candidates)
    for (const TechniqueFigure& f : table) {
      if (f.technique != t) continue;
      if (f.ms < fastest_ms) {
        fastest_ms = f.ms;
        fastest = t;
      }
      if (f.ms <= target && f.rde < best_rde) {
        best_rde = f.rde;
        best = t;
        best_level = f.level;
      }
    }
  TechniqueChoice c;
  if (!best.empty()) {
    c.technique = best;
    reason += best + " chosen: its level " + std::to_string(best_level) + " fits " + fmt(target, 1) + " ms (" +
              fmt(budget_ms, 1) + " less headroom) with the lowest RDE, " + fmt(best_rde, 3);
  } else if (!fastest.empty()) {
    c.technique = fastest;
    reason += "no level fits " + fmt(target, 1) + " ms: " + fastest + " chosen, the fastest (" + fmt(fastest_ms, 1) + " ms)";
  } else {
    // Nothing in the table for the techniques left (a table from another build): the first.
    if (candidates.empty()) return fail(ErrorKind::Internal, "choose_technique: no technique left");
    c.technique = candidates.front();
    reason += "the table has no figures for " + candidates.front() + " or the others left: it is taken as the first";
  }
  c.reason = reason;
  return c;
}

}  // namespace mrgi
