// A technique's quality knobs, declared once per technique as a table of fields of its typed
// level struct (DirLevel, ...): the table makes the ladder's generic knobs (QualityLevel::knobs,
// what `mrgi info --technique` prints) and applies RuntimeSettings::knobs, so no knob is named,
// ranged or documented in two places.
//
// A knob may be set anywhere in the span its technique's ladder covers (lowest to highest value
// over the levels; a switch, 0 or 1): the values the technique's allocations, shaders and tests
// are built for.
// A knob that must be a power of two (a map's side) says so. Beyond that span a value is refused:
// a bigger map or more VPLs than the top level would need shader limits and memory budgets
// nobody has measured. Each setting pins the knob at every level, from start-up, and the
// technique allocates for the largest value of its (set) ladder as always.
#pragma once
#include <algorithm>
#include <cmath>
#include <string>
#include <variant>
#include <vector>

#include "mrgi/expected.h"
#include "mrgi/runtime.h"
#include "technique/technique.h"

namespace mrgi::technique {

template <class L>
struct KnobField {
  const char* name;
  const char* unit;
  std::variant<uint32_t L::*, int L::*, float L::*, double L::*, bool L::*> member;
  bool power_of_two = false;
};

template <class L>
double knob_value(const L& level, const KnobField<L>& f) {
  return std::visit([&](auto m) { return double(level.*m); }, f.member);
}

template <class L>
void set_knob_value(L& level, const KnobField<L>& f, double v) {
  std::visit(
      [&](auto m) {
        using T = std::remove_reference_t<decltype(level.*m)>;
        if constexpr (std::is_same_v<T, bool>) {
          level.*m = v != 0.0;
        } else if constexpr (std::is_integral_v<T>) {
          level.*m = T(std::llround(v));
        } else {
          level.*m = T(v);
        }
      },
      f.member);
}

template <class L>
bool knob_is_integer(const KnobField<L>& f) {
  return !std::holds_alternative<float L::*>(f.member) && !std::holds_alternative<double L::*>(f.member);
}

// The span of field f over the default ladder; a switch (a bool field) spans 0..1 whatever the
// ladder holds: each level builds both of its paths, so turning one on or off is always measured
// ground (an A/B of the feature at any level).
template <class L, class Levels>
std::pair<double, double> knob_span(const Levels& defaults, const KnobField<L>& f) {
  if (std::holds_alternative<bool L::*>(f.member)) return {0.0, 1.0};
  double lo = knob_value(defaults[0], f), hi = lo;
  for (const L& l : defaults) {
    lo = std::min(lo, knob_value(l, f));
    hi = std::max(hi, knob_value(l, f));
  }
  return {lo, hi};
}

template <class L, class Levels, class Fields>
std::vector<Knob> knob_list(const L& level, const Levels& defaults, const Fields& fields) {
  std::vector<Knob> out;
  for (const KnobField<L>& f : fields) {
    const auto [lo, hi] = knob_span(defaults, f);
    out.push_back({f.name, knob_value(level, f), f.unit, lo, hi, f.power_of_two});
  }
  return out;
}

std::string knob_number(double v);  // as a user would type it: "0.5", "256"

// The default ladder with `settings` applied to every level. BadUsage naming the technique, the
// knob and its span for an unknown knob or a value outside the span (or not an integer, or not a
// power of two, where the knob must be one).
template <class L, class Levels, class Fields>
Expected<std::vector<L>> apply_knobs(const std::string& technique, const Levels& defaults, const Fields& fields,
                                     const std::vector<KnobSetting>& settings) {
  std::vector<L> levels(std::begin(defaults), std::end(defaults));
  for (const KnobSetting& s : settings) {
    const KnobField<L>* field = nullptr;
    std::string names;
    for (const KnobField<L>& f : fields) {
      if (s.name == f.name) field = &f;
      names += std::string(names.empty() ? "" : ", ") + f.name;
    }
    if (!field)
      return fail(ErrorKind::BadUsage, "knob '" + s.name + "': technique '" + technique + "' has no such knob (it has " +
                                           names + "; mrgi info --technique " + technique + ")");
    const auto [lo, hi] = knob_span(defaults, *field);
    const std::string what = "knob " + s.name + "=" + knob_number(s.value) + " (" + technique + ", " + field->unit + ")";
    if (!std::isfinite(s.value) || s.value < lo || s.value > hi)
      return fail(ErrorKind::BadUsage, what + ": outside " + knob_number(lo) + ".." + knob_number(hi) +
                                           ", the span of the technique's ladder");
    if (knob_is_integer(*field) && s.value != std::round(s.value))
      return fail(ErrorKind::BadUsage, what + ": must be a whole number");
    const auto n = uint64_t(std::llround(s.value));
    if (field->power_of_two && (n == 0 || (n & (n - 1)) != 0))
      return fail(ErrorKind::BadUsage, what + ": must be a power of two");
    for (L& l : levels) set_knob_value(l, *field, s.value);
  }
  return levels;
}

// The generic ladder of a typed one: names, internal scale, level of detail and the knob list.
template <class L, class Levels, class Fields>
std::vector<QualityLevel> ladder_of(const std::vector<L>& levels, const Levels& defaults, const Fields& fields) {
  std::vector<QualityLevel> out;
  for (const L& l : levels) {
    QualityLevel q;
    q.name = l.name;
    q.internal_scale = l.internal_scale;
    if constexpr (requires { l.mesh_error_px; }) q.mesh_error_px = l.mesh_error_px;
    if constexpr (requires { l.compose_tolerance; }) q.compose_tolerance = l.compose_tolerance;
    q.knobs = knob_list(l, defaults, fields);
    out.push_back(std::move(q));
  }
  return out;
}

}  // namespace mrgi::technique
