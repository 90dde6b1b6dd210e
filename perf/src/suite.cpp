#include "mrgi/perf/suite.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;

namespace mrgi::perf {
namespace {

bool safe_name(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) return false;
  return true;
}

// Relative capture paths are relative to the repository root; a suite in <repo>/perf/ has the
// root as its folder's parent.
fs::path capture_base(const fs::path& suite_path) {
  const fs::path dir = fs::absolute(suite_path).lexically_normal().parent_path();
  if (dir.filename() == "perf") return dir.parent_path();
  return dir;
}

}  // namespace

Expected<std::vector<SuiteScene>> load_suite(const std::string& path) {
  std::ifstream f(path);
  if (!f) return fail(ErrorKind::NotFound, path + ": cannot open the suite file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(f);
  } catch (const nlohmann::json::parse_error& e) {
    return fail(ErrorKind::BadInput, path + ": not valid JSON: " + e.what());
  }
  const nlohmann::json* list = &j;
  if (j.is_object()) {
    if (!j.contains("scenes")) return fail(ErrorKind::BadInput, path + ": the top-level object has no \"scenes\" array");
    list = &j["scenes"];
  }
  if (!list->is_array()) return fail(ErrorKind::BadInput, path + ": \"scenes\" must be an array of scene objects");
  const fs::path base = capture_base(path);
  std::vector<SuiteScene> scenes;
  std::set<std::string> seen;
  for (size_t i = 0; i < list->size(); ++i) {
    const nlohmann::json& s = (*list)[i];
    const std::string where = path + ": scenes[" + std::to_string(i) + "]";
    if (!s.is_object()) return fail(ErrorKind::BadInput, where + ": must be an object");
    auto text = [&](const char* key, bool required, std::string& out) -> Status {
      if (!s.contains(key)) {
        if (required) return fail(ErrorKind::BadInput, where + ": missing required string \"" + key + "\"");
        return ok_status();
      }
      if (!s[key].is_string()) return fail(ErrorKind::BadInput, where + "." + key + ": must be a string");
      out = s[key].get<std::string>();
      return ok_status();
    };
    SuiteScene scene;
    std::string capture;
    MRGI_TRY(text("name", true, scene.name));
    MRGI_TRY(text("capture", true, capture));
    MRGI_TRY(text("description", false, scene.description));
    MRGI_TRY(text("effect", false, scene.effect));
    if (!safe_name(scene.name))
      return fail(ErrorKind::BadInput, where + ".name: '" + scene.name + "' must be non-empty letters, digits, '_', '-' or '.'");
    if (!seen.insert(scene.name).second)
      return fail(ErrorKind::BadInput, where + ".name: '" + scene.name + "' appears twice (names must be unique)");
    if (capture.empty()) return fail(ErrorKind::BadInput, where + ".capture: must not be empty");
    fs::path cap(capture);
    if (cap.is_relative()) cap = base / cap;
    scene.capture = cap.lexically_normal().string();
    scene.set = fs::path(path).stem().string();
    scenes.push_back(std::move(scene));
  }
  if (scenes.empty()) return fail(ErrorKind::BadInput, path + ": the suite lists no scenes");
  return scenes;
}

Expected<std::vector<SuiteScene>> load_suites(const std::string& paths) {
  std::vector<SuiteScene> all;
  std::vector<std::string> from;  // per scene of `all`, its manifest
  size_t start = 0;
  while (start <= paths.size()) {
    const size_t comma = std::min(paths.find(',', start), paths.size());
    const std::string path = paths.substr(start, comma - start);
    start = comma + 1;
    if (path.empty()) return fail(ErrorKind::BadUsage, "--suite: an empty manifest path in '" + paths + "'");
    auto scenes = load_suite(path);
    if (!scenes.ok()) return scenes.error();
    for (SuiteScene& s : *scenes) {
      for (size_t i = 0; i < all.size(); ++i)
        if (all[i].name == s.name)
          return fail(ErrorKind::BadInput, path + ": scene name '" + s.name + "' is also in " + from[i] +
                                               " (names must be unique over the manifests of one run)");
      all.push_back(std::move(s));
      from.push_back(path);
    }
  }
  return all;
}

Expected<std::vector<SuiteScene>> select_scenes(const std::vector<SuiteScene>& suite,
                                                const std::vector<std::string>& names) {
  if (names.empty()) return suite;
  std::vector<SuiteScene> out;
  for (const std::string& n : names) {
    bool found = false;
    for (const SuiteScene& s : suite) found = found || s.name == n;
    if (!found) {
      std::string known;
      for (const SuiteScene& s : suite) known += (known.empty() ? "" : ", ") + s.name;
      return fail(ErrorKind::BadUsage, "--scenes: no scene '" + n + "' in the suite (scenes: " + known + ")");
    }
  }
  for (const SuiteScene& s : suite)
    for (const std::string& n : names)
      if (s.name == n) { out.push_back(s); break; }
  return out;
}

}  // namespace mrgi::perf
