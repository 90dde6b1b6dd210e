#include <string>

#include "technique/baseline/baseline.h"
#include "technique/dir/dir.h"
#include "technique/dlpv/dlpv.h"
#include "technique/dvct/dvct.h"
#include "technique/ssrt/ssrt.h"
#include "technique/technique.h"

namespace mrgi::technique {

// One line per technique; a new technique is a new folder plus one line here (an explicit list:
// self-registering objects in a static library are dropped by the linker when unreferenced).
const std::vector<TechniqueEntry>& registered_techniques() {
  static const std::vector<TechniqueEntry> entries = {
      {"baseline", &baseline_ladder, &create_baseline},
      {"ssrt", &ssrt_ladder, &create_ssrt},
      {"dlpv", &dlpv_ladder, &create_dlpv},
      {"dir", &dir_ladder, &create_dir},
      {"dvct", &dvct_ladder, &create_dvct},
  };
  return entries;
}

Expected<const TechniqueEntry*> find_technique(const std::string& name) {
  std::string known;
  for (const TechniqueEntry& e : registered_techniques()) {
    if (e.name == name) return &e;
    known += (known.empty() ? "" : ", ") + std::string(e.name);
  }
  // docs/DESIGN.md's specular add-on is a stage of every technique, not a technique of its own: the
  // name says where it is instead of "unknown".
  if (name == "specular")
    return fail(ErrorKind::BadUsage, "technique 'specular': mirrors, glass and caustics are a stage of every technique "
                                     "(runtime/src/specular/), on wherever a virtual material is reflective or refractive; "
                                     "choose the technique that lights the rest (" + known +
                                     "), and ResearchSettings::specular (mrgi/research.h; --specular-ablation off) turns the stage off");
  return fail(ErrorKind::BadUsage, "technique '" + name + "' is not known; known techniques: " + known);
}

}  // namespace mrgi::technique
