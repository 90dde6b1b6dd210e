// The scene suite manifest (perf/suite.json): which captures the bench replays.
// Accepted shape: {"scenes": [{"name": ..., "capture": ..., "description": ..., "effect": ...}]}
// (or the bare array). `name` and `capture` are required; `capture` is a folder in capture format
// v1, relative paths resolved against the repository root (the suite file's folder's parent when
// the file sits in perf/, else the suite file's folder). Several manifests can be read as one
// run (load_suites), each scene keeping the name of the set it came from.
#pragma once
#include <string>
#include <vector>

#include "mrgi/expected.h"

namespace mrgi::perf {

struct SuiteScene {
  std::string name;         // unique in the suite; [A-Za-z0-9_.-]+ so it is safe in CSV and paths
  std::string capture;      // absolute path of the capture folder
  std::string description;  // optional
  std::string effect;       // optional: the effect the scene targets
  std::string set;          // the manifest's file name without its extension ("suite", "cycles-heldout")
};

Expected<std::vector<SuiteScene>> load_suite(const std::string& path);
// Comma-separated manifests, their scenes in order; a scene name that two of them use is BadInput
// naming both files.
Expected<std::vector<SuiteScene>> load_suites(const std::string& paths);

// Keeps the scenes named in `names` (all when empty), in suite order; an unknown name is BadUsage.
Expected<std::vector<SuiteScene>> select_scenes(const std::vector<SuiteScene>& suite,
                                                const std::vector<std::string>& names);

}  // namespace mrgi::perf
