// The runtime's layers, read from the includes (README "Architecture"): the shared stages
// (frame/, gi/, recon/, light/, shading/, specular/) never include a technique, no technique
// includes another technique's files (C++ or GLSL), techniques are composed through typed
// inputs (no dynamic_cast of a technique type), and the frame layer is below everything it
// serves. A new include that breaks a rule fails here with the file, the line and the rule.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const fs::path kRoot = fs::path(MRGI_SOURCE_DIR);
const std::set<std::string> kTechniques = {"baseline", "dir", "dlpv", "dvct", "ssrt"};

struct Include {
  std::string file;  // relative to the repository
  int line = 0;
  std::string path;  // as written between the quotes
};

bool source_file(const fs::path& p) {
  static const std::set<std::string> ext = {".h", ".cpp", ".glsl", ".comp", ".vert", ".frag"};
  return ext.count(p.extension().string()) > 0;
}

std::vector<Include> includes_under(const fs::path& dir) {
  static const std::regex include_line(R"(^\s*#\s*include\s*"([^"]+)\")");
  std::vector<Include> out;
  for (const auto& entry : fs::recursive_directory_iterator(kRoot / dir)) {
    if (!entry.is_regular_file() || !source_file(entry.path())) continue;
    std::ifstream in(entry.path());
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
      ++n;
      std::smatch m;
      if (std::regex_search(line, m, include_line))
        out.push_back({fs::relative(entry.path(), kRoot).string(), n, m[1].str()});
    }
  }
  return out;
}

// The first folder of a path below runtime/src/ or shaders/ ("dir" of "runtime/src/technique/dir/dir.h"
// is the technique; "technique" and "dir" of "technique/dir/dir.h" as an include).
std::string technique_of_file(const std::string& file) {
  for (const std::string& t : kTechniques) {
    if (file.rfind("runtime/src/technique/" + t + "/", 0) == 0) return t;
    if (file.rfind("shaders/" + t + "/", 0) == 0) return t;
  }
  return "";
}
std::string technique_of_include(const std::string& path) {
  for (const std::string& t : kTechniques)
    if (path.rfind("technique/" + t + "/", 0) == 0 || path.rfind(t + "/", 0) == 0) return t;
  return "";
}

TEST(Layering, SharedStagesIncludeNoTechnique) {
  std::vector<std::string> broken;
  for (const char* layer : {"frame", "gi", "recon", "light", "shading", "specular", "gpu", "compose", "scene", "image"})
    for (const Include& inc : includes_under(fs::path("runtime/src") / layer))
      if (inc.path.rfind("technique/", 0) == 0 || !technique_of_include(inc.path).empty())
        broken.push_back(inc.file + ":" + std::to_string(inc.line) + " includes " + inc.path);
  EXPECT_TRUE(broken.empty()) << "a shared stage includes a technique (techniques compose shared blocks, "
                                 "not the other way):\n  "
                              << testing::PrintToString(broken);
}

TEST(Layering, SharedShadersIncludeNoTechniqueShader) {
  std::vector<std::string> broken;
  for (const char* layer : {"common", "gi", "shading", "shared", "specular", "recon", "compose", "gbuffer"})
    for (const Include& inc : includes_under(fs::path("shaders") / layer))
      if (!technique_of_include(inc.path).empty())
        broken.push_back(inc.file + ":" + std::to_string(inc.line) + " includes " + inc.path);
  EXPECT_TRUE(broken.empty()) << "a shared shader includes a technique's:\n  " << testing::PrintToString(broken);
}

TEST(Layering, NoTechniqueIncludesAnothersFiles) {
  std::vector<std::string> broken;
  for (const char* dir : {"runtime/src/technique", "shaders"})
    for (const Include& inc : includes_under(dir)) {
      const std::string self = technique_of_file(inc.file), other = technique_of_include(inc.path);
      if (!self.empty() && !other.empty() && self != other)
        broken.push_back(inc.file + ":" + std::to_string(inc.line) + " includes " + inc.path);
    }
  EXPECT_TRUE(broken.empty()) << "a technique includes another technique's files (shared math belongs in "
                                 "shaders/shared/ or gi/, shared blocks in shading/ or gi/):\n  "
                              << testing::PrintToString(broken);
}

TEST(Layering, FrameLayerIncludesOnlyWhatIsBelowIt) {
  // frame/ serves every stage: it may use the GPU layer, the public headers and the
  // shader-shared headers, nothing that is built on it.
  const std::vector<std::string> allowed = {"frame/", "gpu/", "mrgi/", "common/", "shared/"};
  std::vector<std::string> broken;
  for (const Include& inc : includes_under("runtime/src/frame")) {
    bool ok = false;
    for (const std::string& a : allowed) ok = ok || inc.path.rfind(a, 0) == 0;
    if (!ok) broken.push_back(inc.file + ":" + std::to_string(inc.line) + " includes " + inc.path);
  }
  EXPECT_TRUE(broken.empty()) << testing::PrintToString(broken);
}

TEST(Layering, NoDynamicCastOfATechnique) {
  std::vector<std::string> found;
  for (const auto& entry : fs::recursive_directory_iterator(kRoot / "runtime/src")) {
    if (!entry.is_regular_file() || !source_file(entry.path())) continue;
    std::ifstream in(entry.path());
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
      ++n;
      if (line.find("dynamic_cast") != std::string::npos)
        found.push_back(fs::relative(entry.path(), kRoot).string() + ":" + std::to_string(n));
    }
  }
  EXPECT_TRUE(found.empty()) << "techniques are composed through typed inputs, not found by casting: "
                             << testing::PrintToString(found);
}

// The rules above must see the tree: a test that scans nothing passes for the wrong reason.
TEST(Layering, TheScanSeesTheSources) {
  EXPECT_GT(includes_under("runtime/src/technique").size(), 50u);
  EXPECT_GT(includes_under("shaders").size(), 100u);
  EXPECT_EQ(technique_of_include("technique/dir/dir.h"), "dir");
  EXPECT_EQ(technique_of_include("dlpv/volume_lookup.glsl"), "dlpv");
  EXPECT_EQ(technique_of_include("gi/volume_lookup.glsl"), "");
  EXPECT_EQ(technique_of_file("runtime/src/technique/dvct/dvct.cpp"), "dvct");
}

}  // namespace
