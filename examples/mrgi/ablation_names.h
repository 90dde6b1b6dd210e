// The ablation switches of mrgi/research.h by their command-line names, each written once: the
// options' allowed values and the parsing of replay's and bench's flags both read these tables.
#pragma once
#include <string>
#include <vector>

#include "mrgi/research.h"

namespace mrgi::tool {

template <typename A>
struct AblationName {
  const char* name;
  bool A::*flag;
};
inline constexpr AblationName<DlpvAblation> kDlpvAblations[] = {
    {"two-volumes", &DlpvAblation::two_volumes},
    {"no-damping", &DlpvAblation::no_negative_damping},
    {"no-shift", &DlpvAblation::no_half_cell_shift},
    {"no-self-bounce", &DlpvAblation::no_virtual_self_bounce}};
inline constexpr AblationName<DirAblation> kDirAblations[] = {
    {"one-shadow-map", &DirAblation::one_shadow_map},
    {"no-real-only-vpls", &DirAblation::no_real_only_vpls},
    {"one-bounce", &DirAblation::one_bounce},
    {"no-environment-vpls", &DirAblation::no_environment_vpls},
    {"no-temporal-smoothing", &DirAblation::no_temporal_smoothing},
    {"no-caustic-vpls", &DirAblation::no_caustic_vpls}};
inline constexpr AblationName<SpecularAblation> kSpecularAblations[] = {
    {"off", &SpecularAblation::off},
    {"no-back-projection", &SpecularAblation::no_back_projection},
    {"no-depth-test", &SpecularAblation::no_depth_test},
    {"no-caustics", &SpecularAblation::no_caustics}};

template <typename A, size_t N>
void set_ablations(const std::vector<std::string>& given, const AblationName<A> (&names)[N], A& out) {
  for (const std::string& g : given)
    for (const AblationName<A>& n : names)
      if (g == n.name) out.*n.flag = true;
}

template <typename A, size_t N>
std::vector<std::string> ablation_names(const AblationName<A> (&names)[N]) {
  std::vector<std::string> out;
  for (const AblationName<A>& n : names) out.push_back(n.name);
  return out;
}

}  // namespace mrgi::tool
