// Sub-commands of the `mrgi` tool register themselves, one file each (cmd_*.cpp), so adding a
// command touches no other file. Contract for scripts and CI: exit 0 on success, 2 on bad usage,
// 1 on bad input or failure, with a message on stderr.
#pragma once
#include <functional>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "mrgi/expected.h"
#include "mrgi/runtime.h"

namespace mrgi::tool {

// Adds one sub-command (with its options and callback) to the top-level app.
using CommandSetup = void (*)(CLI::App& app);

struct CommandRegistrar {
  CommandRegistrar(const char* name, CommandSetup setup);
};

#define MRGI_COMMAND(name, setup) \
  static ::mrgi::tool::CommandRegistrar mrgi_command_registrar_##name(#name, setup)

// Thrown from a callback to end the command with an exit code and a message on stderr.
struct CommandFailure : std::runtime_error {
  int exit_code;
  CommandFailure(int code, const std::string& message) : std::runtime_error(message), exit_code(code) {}
};

// Writes `text` to PATH.partial and renames it to `path` when complete, so a failed or
// interrupted run never leaves a half-written file under the final name (CommandFailure, exit 1).
void write_text_file(const std::string& path, const std::string& text);

// Exit code for an error kind: BadUsage -> 2, everything else -> 1.
int exit_code_for(ErrorKind kind);
[[noreturn]] void fail_with(const Error& error);

// Unwraps an Expected or ends the command with its error.
template <class T>
T take(Expected<T>&& e) {
  if (!e.ok()) fail_with(e.error());
  return std::move(e).value();
}

// A --level value for `technique`: a number (0 = best), a level name ("fast"), or "last" (the
// cheapest). Anything else ends the command with exit 2 and the list of levels.
// allow_auto: "auto" is kAutoLevel (the scheduler chooses; replay and live).
int resolve_level(const std::string& technique, const std::string& level, bool allow_auto = false);

// --knob NAME=VALUE settings (RuntimeSettings::knobs) for `technique`, checked against its
// ladder; a malformed or refused one ends the command with exit 2 and the knob's span.
std::vector<KnobSetting> parse_knobs(const std::string& technique, const std::vector<std::string>& given);

// The quality options replay and live share: --technique (a name or auto), --level (auto or
// fixed), --budget-ms, --knob. add() declares them; apply() checks them together (exit 2 for a
// combination that cannot be: auto with a fixed level or knobs) and fills the settings.
struct QualityOptions {
  std::string technique = "baseline", level = "auto";
  double budget_ms = 1000.0 / 30.0;
  std::vector<std::string> knobs;
  void add(CLI::App& cmd);
  void apply(RuntimeSettings& settings) const;  // technique, level, frame_budget_ms, knobs
};

// --view and --view-screenshot (live_view.h: the window, its keys), as replay and live take them;
// `frames` says how that command's frames reach the window, `end` when the screenshot is taken.
struct ViewOptions {
  bool view = false;
  std::string screenshot;
  void add(CLI::App& cmd, const std::string& frames, const std::string& end);
};

// --output: the images a replay or live run writes per frame (composite, overlay), for
// ReplayOutput::set_images.
struct OutputImagesOption {
  std::vector<std::string> images{"composite"};
  void add(CLI::App& cmd);
  bool wants(const char* image) const;
};

// --budget-ms's rule, said in words (CLI11's range check prints its raw bounds): a frame budget
// in ms, at least 0.1 and at most 1e6.
CLI::Validator frame_budget_ms_check();

// Progress on stderr for long work (one line, rewritten in place when stderr is a terminal).
void progress(const std::string& what, size_t done, size_t total, double elapsed_s);
// A progress callback (what, done, total) whose elapsed time counts from its own creation.
std::function<void(const std::string&, size_t, size_t)> progress_since_now();

}  // namespace mrgi::tool
