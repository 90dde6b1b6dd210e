// `mrgi synth` in a build without the path tracer (MRGI_WITH_REFERENCE=OFF: Embree not found or
// switched off at configure): the command is listed and says why it cannot run.
#include "commands.h"

namespace mrgi::tool {
namespace {

void setup(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "synth", "Render a synthetic capture (NOT IN THIS BUILD: the path tracer needs libembree-dev)");
  cmd->allow_extras();
  cmd->callback([] {
    throw CommandFailure(1, "synth: this mrgi was built without the path-traced reference (MRGI_WITH_REFERENCE=OFF "
                            "at configure: libembree-dev not found or switched off)");
  });
}

}  // namespace
MRGI_COMMAND(synth, setup);
}  // namespace mrgi::tool
