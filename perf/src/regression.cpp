#include "mrgi/perf/regression.h"

#include <sstream>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <tuple>

#include <nlohmann/json.hpp>

#include "mrgi/perf/stats.h"

namespace mrgi::perf {
namespace {

using Key = std::tuple<std::string, std::string, std::string>;  // scene, technique, level name

std::string key_text(const std::string& scene, const std::string& technique, const std::string& level) {
  return scene + "/" + technique + "/" + level;
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

nlohmann::ordered_json opt_json(const std::optional<double>& v) {
  return v ? nlohmann::ordered_json(*v) : nlohmann::ordered_json(nullptr);
}

// Reads a finite non-negative number (or null when allowed) at `obj[key]`.
Status read_number(const nlohmann::json& obj, const char* key, const std::string& where, bool nullable,
                   std::optional<double>& out) {
  if (!obj.contains(key)) return fail(ErrorKind::BadInput, where + ": missing \"" + key + "\"");
  const nlohmann::json& v = obj[key];
  if (v.is_null() && nullable) {
    out.reset();
    return ok_status();
  }
  if (!v.is_number())
    return fail(ErrorKind::BadInput, where + "." + key + ": must be a number" + (nullable ? " or null" : ""));
  const double d = v.get<double>();
  if (!std::isfinite(d) || d < 0.0)
    return fail(ErrorKind::BadInput, where + "." + key + ": must be finite and >= 0 (got " + num(d) + ")");
  out = d;
  return ok_status();
}

Status read_string(const nlohmann::json& obj, const char* key, const std::string& where, std::string& out) {
  if (!obj.contains(key) || !obj[key].is_string())
    return fail(ErrorKind::BadInput, where + ": \"" + key + "\" must be a string");
  out = obj[key].get<std::string>();
  return ok_status();
}

}  // namespace

Baseline make_baseline(const BenchResult& result, const Tolerances& tolerances) {
  Baseline b;
  b.tolerances = tolerances;
  b.device = result.device;
  b.lp_num_threads = result.lp_num_threads;
  b.commit = result.commit;
  b.frames = result.frames;
  b.warmup = result.warmup;
  b.floor_median_ms = result.floor_median_ms;
  for (const BenchEntry& e : result.entries) {
    BaselineEntry be{e.scene, e.technique, e.level_name, e.level, e.sustained_ratio, {}, {}, e.profiled.min_ratio, {}};
    for (const PassSummary& p : e.passes) be.pass_ratios.emplace_back(p.name, p.time.min_ratio);
    if (e.has_reference) {
      if (e.error.all.rde_defined) be.rde = e.error.all.rde;
      be.delta_rms = e.error.all.delta_rms;
    }
    b.entries.push_back(be);
  }
  return b;
}

Status write_baseline(const std::string& path, const Baseline& b) {
  nlohmann::ordered_json j;  // keeps version and tolerances at the top of the file
  j["version"] = 1;
  j["tolerances"] = {{"ratio_relative", b.tolerances.ratio_relative},
                     {"rde_absolute", b.tolerances.rde_absolute},
                     {"delta_rms_absolute", b.tolerances.delta_rms_absolute},
                     {"ratio_absolute", b.tolerances.ratio_absolute},
                     {"pass_ratio_relative", b.tolerances.pass_ratio_relative},
                     {"pass_min_share", b.tolerances.pass_min_share}};
  j["source"] = {{"device", b.device},   {"lp_num_threads", b.lp_num_threads}, {"commit", b.commit},
                 {"frames", b.frames},   {"warmup", b.warmup},                 {"floor_median_ms", b.floor_median_ms}};
  nlohmann::ordered_json entries = nlohmann::ordered_json::array();
  for (const BaselineEntry& e : b.entries) {
    nlohmann::ordered_json passes = nlohmann::ordered_json::object();
    for (const auto& [name, ratio] : e.pass_ratios) passes[name] = ratio;
    entries.push_back({{"scene", e.scene},
                       {"technique", e.technique},
                       {"level", e.level},
                       {"level_name", e.level_name},
                       {"ratio_to_floor", e.ratio_to_floor},
                       {"rde", opt_json(e.rde)},
                       {"delta_rms", opt_json(e.delta_rms)},
                       {"profiled_ratio", e.profiled_ratio},
                       {"pass_ratios", passes}});
  }
  j["entries"] = entries;
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp);
    if (!f) return fail(ErrorKind::BadInput, tmp + ": cannot open for writing");
    f << j.dump(2) << "\n";
    if (!f) return fail(ErrorKind::Device, tmp + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) return fail(ErrorKind::Device, path + ": rename failed: " + ec.message());
  return ok_status();
}

Expected<Baseline> load_baseline(const std::string& path) {
  std::ifstream f(path);
  if (!f) return fail(ErrorKind::NotFound, path + ": cannot open the baseline file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(f);
  } catch (const nlohmann::json::parse_error& e) {
    return fail(ErrorKind::BadInput, path + ": not valid JSON: " + e.what());
  }
  if (!j.is_object()) return fail(ErrorKind::BadInput, path + ": must be a JSON object");
  if (!j.contains("version") || j["version"] != 1)
    return fail(ErrorKind::BadInput, path + ": \"version\" must be 1");
  Baseline b;
  if (!j.contains("tolerances") || !j["tolerances"].is_object())
    return fail(ErrorKind::BadInput, path + ": missing \"tolerances\" object");
  const std::string tw = path + ": tolerances";
  std::optional<double> v;
  MRGI_TRY(read_number(j["tolerances"], "ratio_relative", tw, false, v));
  b.tolerances.ratio_relative = *v;
  MRGI_TRY(read_number(j["tolerances"], "rde_absolute", tw, false, v));
  b.tolerances.rde_absolute = *v;
  MRGI_TRY(read_number(j["tolerances"], "delta_rms_absolute", tw, false, v));
  b.tolerances.delta_rms_absolute = *v;
  // Optional (baselines written before the per-pass rule have neither): the defaults apply.
  if (j["tolerances"].contains("ratio_absolute")) {
    MRGI_TRY(read_number(j["tolerances"], "ratio_absolute", tw, false, v));
    b.tolerances.ratio_absolute = *v;
  }
  if (j["tolerances"].contains("pass_ratio_relative")) {
    MRGI_TRY(read_number(j["tolerances"], "pass_ratio_relative", tw, false, v));
    b.tolerances.pass_ratio_relative = *v;
  }
  if (j["tolerances"].contains("pass_min_share")) {
    MRGI_TRY(read_number(j["tolerances"], "pass_min_share", tw, false, v));
    b.tolerances.pass_min_share = *v;
  }
  if (j.contains("source") && j["source"].is_object()) {
    const auto& s = j["source"];
    b.device = s.value("device", "");
    b.lp_num_threads = s.value("lp_num_threads", "");
    b.commit = s.value("commit", "");
    b.frames = s.value("frames", 0);
    b.warmup = s.value("warmup", 0);
    b.floor_median_ms = s.value("floor_median_ms", 0.0);
  }
  if (!j.contains("entries") || !j["entries"].is_array())
    return fail(ErrorKind::BadInput, path + ": missing \"entries\" array");
  std::map<Key, size_t> seen;
  for (size_t i = 0; i < j["entries"].size(); ++i) {
    const nlohmann::json& e = j["entries"][i];
    const std::string where = path + ": entries[" + std::to_string(i) + "]";
    if (!e.is_object()) return fail(ErrorKind::BadInput, where + ": must be an object");
    BaselineEntry be;
    MRGI_TRY(read_string(e, "scene", where, be.scene));
    MRGI_TRY(read_string(e, "technique", where, be.technique));
    MRGI_TRY(read_string(e, "level_name", where, be.level_name));
    if (!e.contains("level") || !e["level"].is_number_integer() || e["level"].get<int>() < 0)
      return fail(ErrorKind::BadInput, where + ".level: must be an integer >= 0");
    be.level = e["level"].get<int>();
    MRGI_TRY(read_number(e, "ratio_to_floor", where, false, v));
    be.ratio_to_floor = *v;
    if (!(be.ratio_to_floor > 0.0)) return fail(ErrorKind::BadInput, where + ".ratio_to_floor: must be > 0");
    MRGI_TRY(read_number(e, "rde", where, true, be.rde));
    MRGI_TRY(read_number(e, "delta_rms", where, true, be.delta_rms));
    if (e.contains("profiled_ratio")) {
      MRGI_TRY(read_number(e, "profiled_ratio", where, false, v));
      be.profiled_ratio = *v;
    }
    if (e.contains("pass_ratios")) {
      if (!e["pass_ratios"].is_object())
        return fail(ErrorKind::BadInput, where + ".pass_ratios: must be an object of pass name -> ratio");
      for (const auto& [name, value] : e["pass_ratios"].items()) {
        MRGI_TRY(read_number(e["pass_ratios"], name.c_str(), where + ".pass_ratios", false, v));
        be.pass_ratios.emplace_back(name, *v);
      }
    }
    const Key k{be.scene, be.technique, be.level_name};
    if (!seen.emplace(k, i).second)
      return fail(ErrorKind::BadInput, where + ": " + key_text(be.scene, be.technique, be.level_name) +
                                           " appears twice (also entries[" + std::to_string(seen[k]) + "])");
    b.entries.push_back(std::move(be));
  }
  return b;
}

CheckReport check_against(const BenchResult& result, const Baseline& b) {
  CheckReport rep;
  const Tolerances& tol = b.tolerances;
  // Medians over different numbers of frames, after different warm-ups, are not comparable: a
  // 4-frame run after 1 warm-up frame read 35-45 % slower than the 16-after-4 baseline of the
  // same commit on this machine (first frames still fill lavapipe's shader caches), which the
  // ratio tolerance would report as a regression. A baseline without these fields (0) is old
  // and is compared as before.
  if (b.frames > 0 && (result.frames != b.frames || result.warmup != b.warmup))
    rep.violations.push_back("the run measured " + std::to_string(result.frames) + " frames after " +
                             std::to_string(result.warmup) + " warm-up, the baseline " +
                             std::to_string(b.frames) + " after " + std::to_string(b.warmup) +
                             ": the medians are not comparable (run with --frames " +
                             std::to_string(b.frames) + " --warmup " + std::to_string(b.warmup) + ")");
  std::map<Key, const BaselineEntry*> base;
  for (const BaselineEntry& e : b.entries) base[Key{e.scene, e.technique, e.level_name}] = &e;
  std::map<Key, bool> matched;
  std::map<std::string, std::vector<double>> pass_changes;  // pass -> run / baseline, per entry
  for (size_t index = 0; index < result.entries.size(); ++index) {
    const BenchEntry& e = result.entries[index];
    const Key k{e.scene, e.technique, e.level_name};
    const std::string name = key_text(e.scene, e.technique, e.level_name);
    const size_t findings_before = rep.violations.size();
    bool timing = false;
    auto it = base.find(k);
    if (it == base.end()) {
      rep.missing_in_baseline.push_back(name);
      continue;
    }
    matched[k] = true;
    rep.compared += 1;
    const BaselineEntry& be = *it->second;
    const double ratio_limit = be.ratio_to_floor * (1.0 + tol.ratio_relative) + tol.ratio_absolute;
    if (!(e.sustained_ratio <= ratio_limit)) {
      timing = true;
      rep.violations.push_back(name + ": sustained frame time ratio to floor " + num(e.sustained_ratio) + " > " +
                               num(ratio_limit) + " (baseline " + num(be.ratio_to_floor) + " + " +
                               num(100.0 * tol.ratio_relative) + " % + " + num(tol.ratio_absolute) + " floor)");
    }
    // Per pass (judged over the whole run below): the change of each checked pass's fastest
    // frame against the baseline's, in every entry that runs it.
    for (const auto& [pass, base_ratio] : be.pass_ratios) {
      if (!(be.profiled_ratio > 0.0) || !(base_ratio > 0.0) || base_ratio < tol.pass_min_share * be.profiled_ratio)
        continue;
      if (pass.rfind("host", 0) == 0) continue;  // the host's own work: not a pass of the graph
      for (const PassSummary& p : e.passes)
        if (p.name == pass && p.time.min_ratio > 0.0) pass_changes[pass].push_back(p.time.min_ratio / base_ratio);
    }
    const bool have_rde = e.has_reference && e.error.all.rde_defined;
    if (be.rde) {
      if (!have_rde) {
        rep.violations.push_back(name + ": RDE is undefined in this run (no reference, or nothing should change) "
                                        "but the baseline has " + num(*be.rde));
      } else if (!(e.error.all.rde <= *be.rde + tol.rde_absolute)) {
        rep.violations.push_back(name + ": RDE " + num(e.error.all.rde) + " > " + num(*be.rde + tol.rde_absolute) +
                                 " (baseline " + num(*be.rde) + " + " + num(tol.rde_absolute) + ")");
      }
    } else if (be.delta_rms) {
      // Nothing should change in this scene: compare how much the output changed anyway.
      if (!e.has_reference) {
        rep.violations.push_back(name + ": the run has no reference frames but the baseline has error figures");
      } else if (!(e.error.all.delta_rms <= *be.delta_rms + tol.delta_rms_absolute)) {
        rep.violations.push_back(name + ": delta RMS " + num(e.error.all.delta_rms) + " > " +
                                 num(*be.delta_rms + tol.delta_rms_absolute) + " (baseline " + num(*be.delta_rms) +
                                 " + " + num(tol.delta_rms_absolute) + "; RDE undefined)");
      }
    }
    if (timing && rep.violations.size() == findings_before + 1) rep.timing_only.push_back(index);
  }
  for (const BaselineEntry& e : b.entries)
    if (!matched.count(Key{e.scene, e.technique, e.level_name}))
      rep.missing_in_run.push_back(key_text(e.scene, e.technique, e.level_name));
  // The per-pass rule: a pass's median change over the entries that run it, relative to the
  // median change of every checked pass in the run. Load on a shared machine slows whole runs
  // and whole scenes (the floor does not scale with them: it is a tiny pass), which moves every
  // pass together; a code change in one pass moves that pass alone, in every entry it runs in.
  if (!pass_changes.empty()) {
    std::vector<double> all;
    for (const auto& [pass, changes] : pass_changes) all.insert(all.end(), changes.begin(), changes.end());
    const double run_change = median(all);
    for (const auto& [pass, changes] : pass_changes) {
      const double relative = median(changes) / run_change;
      if (!(relative <= 1.0 + tol.pass_ratio_relative))
        rep.violations.push_back("pass " + pass + ": median change over its " + std::to_string(changes.size()) +
                                 " entries x" + num(median(changes)) + " against x" + num(run_change) +
                                 " for every checked pass: relative x" + num(relative) + " > x" +
                                 num(1.0 + tol.pass_ratio_relative));
    }
  }
  rep.subset_run = result.subset;
  rep.passed = rep.violations.empty() && rep.compared > 0 && (result.subset || rep.missing_in_run.empty());
  return rep;
}

std::string CheckReport::summary() const {
  std::string s = std::string("regression check ") + (passed ? "PASSED" : "FAILED") + ": " +
                  std::to_string(compared) + " entries compared, " + std::to_string(violations.size()) +
                  " violations\n";
  if (compared == 0) s += "  nothing compared: no run entry has a baseline entry\n";
  for (const auto& v : violations) s += "  violation: " + v + "\n";
  for (const auto& m : missing_in_run)
    s += std::string(subset_run ? "  in the baseline, not in this (restricted) run: " : "  violation: in the baseline, not run: ") + m + "\n";
  for (const auto& m : missing_in_baseline) s += "  in this run, not in the baseline: " + m + "\n";
  for (const auto& n : notes) s += "  note: " + n + "\n";
  return s;
}

std::string xml_escape(const std::string& t) {
  std::string o;
  for (char c : t) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string junit_xml(const BenchResult& result, const CheckReport& report) {
  // One test case per run entry (its findings name it first: "scene/technique/level: ..."),
  // one for the run-wide pass rule and one for the run as a whole (settings, missing entries).
  struct Case {
    std::string name;
    std::vector<std::string> failures;
  };
  std::vector<Case> cases;
  for (const BenchEntry& e : result.entries) cases.push_back({key_text(e.scene, e.technique, e.level_name), {}});
  Case passes{"passes (whole run)", {}}, run{"run", {}};
  for (const std::string& v : report.violations) {
    bool placed = false;
    for (Case& c : cases)
      if (v.compare(0, c.name.size() + 1, c.name + ":") == 0) {
        c.failures.push_back(v);
        placed = true;
        break;
      }
    if (placed) continue;
    (v.rfind("pass ", 0) == 0 ? passes : run).failures.push_back(v);
  }
  if (!report.subset_run)
    for (const std::string& m : report.missing_in_run) run.failures.push_back("missing in the run: " + m);
  if (report.compared == 0) run.failures.push_back("nothing compared: no run entry has a baseline entry");
  cases.push_back(passes);
  cases.push_back(run);
  size_t failed = 0;
  for (const Case& c : cases) failed += c.failures.empty() ? 0 : 1;
  std::ostringstream o;
  o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  o << "<testsuites name=\"mrgi bench --check\" tests=\"" << cases.size() << "\" failures=\"" << failed << "\">\n";
  o << "  <testsuite name=\"mrgi.bench.regression\" tests=\"" << cases.size() << "\" failures=\"" << failed << "\">\n";
  for (const Case& c : cases) {
    o << "    <testcase classname=\"mrgi.bench\" name=\"" << xml_escape(c.name) << "\"";
    if (c.failures.empty()) {
      o << "/>\n";
      continue;
    }
    o << ">\n";
    for (const std::string& f : c.failures)
      o << "      <failure message=\"" << xml_escape(f) << "\">" << xml_escape(f) << "</failure>\n";
    o << "    </testcase>\n";
  }
  for (const std::string& n : report.notes) o << "    <system-out>" << xml_escape(n) << "</system-out>\n";
  o << "  </testsuite>\n</testsuites>\n";
  return o.str();
}

}  // namespace mrgi::perf
