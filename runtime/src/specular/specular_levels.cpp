// The specular stage's ladder (specular.h SpecularLevel: what each level's fields mean and why
// the fast level's values) and its ablation settings.
#include "specular/specular.h"

namespace mrgi::specular {

const std::array<SpecularLevel, 3>& specular_levels() {
  static const std::array<SpecularLevel, 3> levels = {{
      {"paper", 512, 4, 24, 4, 16, 0.0f, 1, 512, 1, 1, true, 0},
      {"high", 256, 2, 16, 3, 12, 0.0f, 1, 256, 1, 1, true, 0},
      {"fast", 96, 2, 10, 2, 8, 0.1f, 8, 128, 16, 2, false, 512},
  }};
  return levels;
}

SpecularSettings settings_for(const SpecularAblation& ablation) {
  SpecularSettings s;
  s.back_projection = !ablation.no_back_projection;
  s.depth_test = !ablation.no_depth_test;
  s.caustics = !ablation.no_caustics;
  return s;
}

const SpecularLevel& specular_level_for(int technique_level, int technique_levels) {
  const auto& l = specular_levels();
  if (technique_level <= 0) return l[0];
  if (technique_level >= technique_levels - 2) return l[2];
  return l[1];
}

}  // namespace mrgi::specular
