// mrgi: the command-line tool. Sub-commands live in cmd_*.cpp and register themselves.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <map>

#include "commands.h"

#include <cstdio>
#include <fstream>
#include "mrgi/runtime.h"
#include "mrgi/version.h"

namespace mrgi::tool {
namespace {
std::map<std::string, CommandSetup>& registry() {
  static std::map<std::string, CommandSetup> r;
  return r;
}
}  // namespace

CommandRegistrar::CommandRegistrar(const char* name, CommandSetup setup) { registry()[name] = setup; }

void write_text_file(const std::string& path, const std::string& text) {
  const std::string partial = path + ".partial";
  {
    std::ofstream f(partial);
    f << text;
    if (!f) throw CommandFailure(1, partial + ": cannot write");
  }
  if (std::rename(partial.c_str(), path.c_str()) != 0)
    throw CommandFailure(1, path + ": cannot move the finished file into place");
}

int exit_code_for(ErrorKind kind) { return kind == ErrorKind::BadUsage ? 2 : 1; }

void fail_with(const Error& error) {
  throw CommandFailure(exit_code_for(error.kind), std::string(to_string(error.kind)) + ": " + error.message);
}

int resolve_level(const std::string& technique, const std::string& level, bool allow_auto) {
  auto levels = take(technique_levels(technique));
  if (level == "last") return int(levels.size()) - 1;
  if (level == "auto") {
    if (!allow_auto) throw CommandFailure(2, "--level auto: this command runs one fixed level (a number, a name, or 'last')");
    return kAutoLevel;
  }
  for (size_t i = 0; i < levels.size(); ++i)
    if (levels[i] == level) return int(i);
  char* end = nullptr;
  const long n = std::strtol(level.c_str(), &end, 10);
  if (level.empty() || *end != '\0' || n < 0 || n >= long(levels.size())) {
    std::string names;
    for (size_t i = 0; i < levels.size(); ++i) names += (i ? ", " : "") + std::to_string(i) + "=" + levels[i];
    throw CommandFailure(2, "--level '" + level + "': technique '" + technique + "' has levels " + names +
                                (allow_auto ? " (a number, a name, 'last', or 'auto': the scheduler chooses)"
                                            : " (a number, a name, or 'last')"));
  }
  return int(n);
}

std::vector<KnobSetting> parse_knobs(const std::string& technique, const std::vector<std::string>& given) {
  std::vector<KnobSetting> knobs;
  for (const std::string& g : given) {
    const size_t eq = g.find('=');
    char* end = nullptr;
    const double v = eq == std::string::npos ? 0.0 : std::strtod(g.c_str() + eq + 1, &end);
    if (eq == std::string::npos || eq == 0 || eq + 1 == g.size() || *end != '\0')
      throw CommandFailure(2, "--knob '" + g + "': expected NAME=VALUE, e.g. --knob vpls=128 (mrgi info --technique " +
                                  technique + " lists the knobs)");
    knobs.push_back({g.substr(0, eq), v});
  }
  // Refused here, before a capture is opened or a device started, with the knob's span.
  take(technique_ladder(technique, knobs));
  return knobs;
}

void OutputImagesOption::add(CLI::App& cmd) {
  cmd.add_option("--output", images,
                 "images written per frame, comma-separated: composite (frames/: the camera frame with the objects and "
                 "their light, default), overlay (overlay/: premultiplied RGBA for a passthrough compositor to blend "
                 "over its own video; mrgi/overlay.h gives the blend)")
      ->delimiter(',')
      ->check(CLI::IsMember({"composite", "overlay"}));
}

bool OutputImagesOption::wants(const char* image) const {
  return std::find(images.begin(), images.end(), image) != images.end();
}

void QualityOptions::add(CLI::App& cmd) {
  cmd.add_option("--technique,-t", technique, "technique: " + [] {
    std::string s;
    for (auto& n : technique_names()) s += (s.empty() ? "" : ", ") + n;
    return s + ", or auto (chosen for the scene and the budget; the first frame's notes say why)";
  }())->capture_default_str();
  cmd.add_option("--level,-l", level,
                 "quality level: 'auto' = the scheduler chooses the level and internal resolution every frame to "
                 "hold --budget-ms; or fixed: 0 = best, N, a level name, or 'last' = cheapest")
      ->capture_default_str();
  cmd.add_option("--budget-ms", budget_ms, "frame budget the scheduler holds, ms (--level auto)")
      ->capture_default_str()
      ->check(frame_budget_ms_check());
  cmd.add_option("--knob", knobs,
                 "set one quality knob at every level, NAME=VALUE (repeatable; mrgi info --technique T lists them "
                 "with their spans)");
}

CLI::Validator frame_budget_ms_check() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (text.empty() || *end != '\0' || !(v >= 0.1 && v <= 1e6))
          return "'" + text + "' is not a frame budget: give the milliseconds a frame may take, at least 0.1 and at "
                 "most 1e6 (33.3 holds 30 fps, 16.7 holds 60 fps)";
        return std::string();
      },
      "MS in [0.1, 1e6]", "frame budget");
}

void QualityOptions::apply(RuntimeSettings& settings) const {
  if (technique == "auto" && level != "auto")
    throw CommandFailure(2, "--technique auto: the level is the scheduler's (--level auto)");
  if (technique == "auto" && !knobs.empty())
    throw CommandFailure(2, "--knob: name a technique (knobs are a technique's own), not --technique auto");
  settings.technique = technique;
  settings.level = technique == "auto" ? kAutoLevel : resolve_level(technique, level, true);
  settings.frame_budget_ms = budget_ms;
  if (!knobs.empty()) settings.knobs = parse_knobs(technique, knobs);
}

void progress(const std::string& what, size_t done, size_t total, double elapsed_s) {
  const double eta = done > 0 ? elapsed_s / double(done) * double(total - done) : 0.0;
  const bool tty = isatty(STDERR_FILENO);
  std::fprintf(stderr, "%s%s: %zu/%zu (%.0f%%), %.1f s elapsed, ETA %.1f s%s", tty ? "\r" : "",
               what.c_str(), done, total, total ? 100.0 * double(done) / double(total) : 100.0,
               elapsed_s, eta, tty ? (done == total ? "\n" : "") : "\n");
  std::fflush(stderr);
}

std::function<void(const std::string&, size_t, size_t)> progress_since_now() {
  const auto t0 = std::chrono::steady_clock::now();
  return [t0](const std::string& what, size_t done, size_t total) {
    progress(what, done, total, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  };
}

}  // namespace mrgi::tool

int main(int argc, char** argv) {
  using namespace mrgi::tool;
  CLI::App app{"mrgi: mixed-reality global illumination runtime (Vulkan, differential rendering)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("mrgi ") + mrgi::version());
  for (auto& [name, setup] : registry()) setup(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; usage errors exit 2 (the tool's contract).
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const CommandFailure& f) {
    std::cerr << "mrgi: " << f.what() << "\n";
    return f.exit_code;
  } catch (const std::exception& e) {
    std::cerr << "mrgi: internal error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
