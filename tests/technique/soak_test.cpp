// Soak: every technique at its cheapest level runs hundreds of frames with a
// moving camera without growing executable code or memory after start-up. lavapipe 22.3 compiled
// a shader per bind where a loop's bound was a uniform (shaders/common/opaque_uniform.glsl):
// ssrt_tsdf_fuse added one executable mapping per frame and RSS grew without bound.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "capture/temp_dir.h"
#include "mrgi/runtime.h"
#include "synthetic_scene.h"

namespace mrgi::test {
namespace {

// Executable mappings and resident set of this process (/proc/self).
size_t executable_mappings() {
  std::ifstream maps("/proc/self/maps");
  size_t n = 0;
  for (std::string line; std::getline(maps, line);) n += line.find(" r-xp ") != std::string::npos;
  return n;
}
double rss_mib() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0.0;
}

// Under AddressSanitizer freed memory sits in its quarantine (256 MiB by default) before reuse, so
// resident memory grows by design; there the leak check at exit stands in for the RSS bound.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

TEST(RuntimeSoak, EveryTechniqueRunsFramesWithoutGrowingCodeOrMemory) {
  for (const std::string& technique : technique_names()) {
    SCOPED_TRACE(technique);
    mrgi::testing::TempDir dir;
    const SyntheticScene scene = SyntheticScene::create(dir.str());
    RuntimeSettings s;
    s.technique = technique;
    auto rt = create_runtime(s, scene.cameras(), scene.scene);
    if (!rt.ok() && rt.error().kind == ErrorKind::NotImplemented) continue;  // named, not built yet
    ASSERT_TRUE(rt.ok()) << rt.error().message;
    ASSERT_TRUE((*rt)->set_level(int((*rt)->level_names().size()) - 1).ok());
    size_t maps_start = 0;
    double rss_start = 0.0;
    const int warmup = 40, frames = 400;
    for (int i = 0; i < warmup + frames; ++i) {
      InputFrame f = scene.frame(i);
      // The camera sways by up to 4 cm, so the volume fuses and the views are ray-cast anew.
      Pose p = f.pose ? *f.pose : scene.pose;
      p.translation.x += 0.002 * double(i % 20);
      f.pose = p;
      auto out = (*rt)->process(f);
      ASSERT_TRUE(out.ok()) << out.error().message;
      if (i + 1 == warmup) {
        ASSERT_TRUE((*rt)->flush().ok());
        maps_start = executable_mappings();
        rss_start = rss_mib();
      }
    }
    ASSERT_TRUE((*rt)->flush().ok());
    EXPECT_LE(executable_mappings(), maps_start + 2) << "compiled code grew over " << frames << " frames";
    if (!kAddressSanitizer) {
      EXPECT_LE(rss_mib(), rss_start + 16.0) << "resident memory grew over " << frames << " frames";
    }
  }
}

}  // namespace
}  // namespace mrgi::test
