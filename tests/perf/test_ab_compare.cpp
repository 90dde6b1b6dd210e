// The A/B comparison (mrgi/perf/ab_compare.h): its manifest's sets and refusals, and a short
// comparison of the built mrgi against itself through `bench --compare` (both workers, the
// interleaved measurements, the four outputs, no alarm), and a base that is no mrgi worker
// refused by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "capture/temp_dir.h"
#include "mrgi/perf/ab_compare.h"
#include "mrgi/perf/suite.h"
#include "mrgi/runtime.h"

using mrgi::testing::TempDir;
namespace fs = std::filesystem;
namespace perf = mrgi::perf;

namespace {

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

}  // namespace

// Both sets of the repository's manifest name suite scenes and levels the techniques have; the
// quick set holds every technique.
TEST(AbCompare, ManifestSetsNameRealEntries) {
  const std::string manifest = std::string(MRGI_SOURCE_DIR) + "/perf/compare.json";
  auto suite = perf::load_suites(std::string(MRGI_SOURCE_DIR) + "/perf/suite.json");
  ASSERT_TRUE(suite.ok()) << suite.error().message;
  for (const char* set : {"quick", "full"}) {
    auto entries = perf::load_compare_set(manifest, set);
    ASSERT_TRUE(entries.ok()) << entries.error().message;
    std::set<std::string> techniques;
    int schedulers = 0;
    for (const perf::AbEntry& e : *entries) {
      EXPECT_TRUE(perf::select_scenes(*suite, {e.scene}).ok()) << set << ": " << e.scene;
      auto levels = mrgi::technique_levels(e.technique);
      ASSERT_TRUE(levels.ok()) << e.technique;
      if (e.level != "auto") {  // the scheduler's entry
        EXPECT_NE(std::find(levels->begin(), levels->end(), e.level), levels->end()) << e.technique << " " << e.level;
      }
      schedulers += e.level == "auto" ? 1 : 0;
      techniques.insert(e.technique);
    }
    EXPECT_EQ(techniques.size(), mrgi::technique_names().size()) << set;
    EXPECT_EQ(schedulers, 1) << set << ": the scheduler's share on the sample (desk_spot)";
  }
}

TEST(AbCompare, ManifestRefusalsNameTheFieldAndRule) {
  TempDir dir;
  const fs::path p = fs::path(dir.str()) / "compare.json";
  auto refused = [&](const std::string& text, const std::string& set, const std::string& expected) {
    write(p, text);
    auto r = perf::load_compare_set(p.string(), set);
    ASSERT_FALSE(r.ok()) << text;
    EXPECT_NE(r.error().message.find(expected), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(p.string()), std::string::npos) << r.error().message;
  };
  refused("{", "quick", "not JSON");
  refused(R"({"version":2,"sets":{}})", "quick", "'version' must be 1");
  refused(R"({"version":1})", "quick", "'sets'");
  refused(R"({"version":1,"sets":{"full":[{"scene":"a","technique":"b","level":"c"}]}})", "quick",
          "no set 'quick' (sets: full)");
  refused(R"({"version":1,"sets":{"quick":[]}})", "quick", "non-empty array");
  refused(R"({"version":1,"sets":{"quick":[{"scene":"a","technique":"b"}]}})", "quick", "sets.quick[0].level");
  auto missing = perf::load_compare_set((fs::path(dir.str()) / "absent.json").string(), "quick");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("cannot be read"), std::string::npos);
}

// The built mrgi against itself on one entry, as a user runs it: exit 0, the four outputs, the
// quantities judged (sustained and CPU ms and the main passes), no alarm. Two pairs cannot alarm
// in a family this size (the report says so), so this checks the machinery, not the machine.
TEST(AbCompare, BuildAgainstItselfWritesTheReport) {
  if (!fs::exists(MRGI_TOOL)) GTEST_SKIP() << "mrgi tool not built at " << MRGI_TOOL;
  TempDir dir;
  const fs::path out = fs::path(dir.str()) / "compare";
  const std::string cmd = std::string("cd ") + MRGI_SOURCE_DIR + " && LP_NUM_THREADS=2 timeout 300 " + MRGI_TOOL +
                          " bench --compare " + MRGI_TOOL +
                          " --scenes desk_spot --techniques baseline --levels lowest --pairs 2 --frames 2 --warmup 1"
                          " --profile-frames 1 -q -o " + out.string() + " > " + (fs::path(dir.str()) / "log").string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << std::ifstream(fs::path(dir.str()) / "log").rdbuf();
  for (const char* f : {"compare.md", "compare.json", "junit.xml", "ratios.png"}) EXPECT_TRUE(fs::exists(out / f)) << f;
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(out / "compare.json"));
  EXPECT_EQ(j["alarms"], 0);
  EXPECT_EQ(j["pairs"], 2);
  std::set<std::string> metrics;
  for (const auto& q : j["quantities"]) {
    metrics.insert(q["metric"].get<std::string>());
    EXPECT_EQ(q["base"].size(), size_t(2));
    EXPECT_EQ(q["candidate"].size(), size_t(2));
  }
  EXPECT_TRUE(metrics.count("sustained_ms"));
  EXPECT_TRUE(metrics.count("cpu_ms"));
  EXPECT_TRUE(metrics.count("pass:shade_direct"));
  std::stringstream md;
  md << std::ifstream(out / "compare.md").rdbuf();
  EXPECT_NE(md.str().find("no quantity of a family"), std::string::npos);  // 2 pairs cannot alarm
}

// The scheduler's entry (level auto) on the sample: judged by its frames per frame within the
// budget alone ((n + 2) / (k + 1) of each measurement's n = 40 frames), not by time.
TEST(AbCompare, SchedulerEntryIsJudgedByItsShareWithinTheBudget) {
  if (!fs::exists(MRGI_TOOL)) GTEST_SKIP() << "mrgi tool not built at " << MRGI_TOOL;
  TempDir dir;
  const fs::path out = fs::path(dir.str()) / "compare";
  const std::string cmd = std::string("cd ") + MRGI_SOURCE_DIR + " && LP_NUM_THREADS=2 timeout 300 " + MRGI_TOOL +
                          " bench --compare " + MRGI_TOOL + " --scenes desk_spot --techniques baseline --levels auto --pairs 2 -q -o " +
                          out.string() + " > " + (fs::path(dir.str()) / "log").string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << std::ifstream(fs::path(dir.str()) / "log").rdbuf();
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(out / "compare.json"));
  ASSERT_EQ(j["quantities"].size(), 1u);
  const auto& q = j["quantities"][0];
  EXPECT_EQ(q["metric"], perf::kSchedulerMetric);
  EXPECT_EQ(q["level"], "auto");
  for (const char* side : {"base", "candidate"}) {
    ASSERT_EQ(q[side].size(), 2u) << side;
    for (const auto& v : q[side]) {
      ASSERT_TRUE(v.is_number()) << side;
      // (40 + 2) / (k + 1) for a whole count k of 0..40 frames within the budget.
      const double k = 42.0 / v.get<double>() - 1.0;
      EXPECT_NEAR(k, std::round(k), 1e-9) << side << " " << v;
      EXPECT_GE(k, -1e-9) << side;
      EXPECT_LE(k, 40.0 + 1e-9) << side;
    }
  }
}

// A base that does not speak the worker protocol is refused naming it; nothing is written.
TEST(AbCompare, BaseThatIsNoWorkerIsRefused) {
  if (!fs::exists(MRGI_TOOL)) GTEST_SKIP() << "mrgi tool not built at " << MRGI_TOOL;
  TempDir dir;
  const fs::path out = fs::path(dir.str()) / "compare";
  const fs::path log = fs::path(dir.str()) / "log";
  const std::string cmd = std::string("cd ") + MRGI_SOURCE_DIR + " && timeout 120 " + MRGI_TOOL +
                          " bench --compare /bin/true --scenes desk_spot --techniques baseline --levels lowest -q -o " +
                          out.string() + " > " + log.string() + " 2>&1";
  EXPECT_NE(std::system(cmd.c_str()), 0);
  std::stringstream text;
  text << std::ifstream(log).rdbuf();
  EXPECT_NE(text.str().find("/bin/true: did not answer as an mrgi bench worker"), std::string::npos) << text.str();
  EXPECT_FALSE(fs::exists(out));
}

// A pass over the rest of its measurement: the machine's drift (every pass 30 % slower) leaves
// it, a 10 % slower pass raises it by 10 %, another pass slowing lowers it; a missing pass is NaN.
TEST(AbCompare, PassOverRestKeepsThePassAndDropsTheDrift) {
  const std::map<std::string, double> base = {{"a", 2.0}, {"b", 6.0}, {"c", 2.0}};
  const double r = perf::pass_over_rest(base, "a");
  EXPECT_DOUBLE_EQ(r, 0.25);
  std::map<std::string, double> drift = base;
  for (auto& [name, ms] : drift) ms *= 1.3;
  EXPECT_NEAR(perf::pass_over_rest(drift, "a"), r, 1e-12);
  std::map<std::string, double> slower = base;
  slower["a"] *= 1.1;
  EXPECT_NEAR(perf::pass_over_rest(slower, "a") / r, 1.1, 1e-12);
  std::map<std::string, double> other = base;
  other["b"] *= 1.1;
  EXPECT_LT(perf::pass_over_rest(other, "a"), r);
  EXPECT_TRUE(std::isnan(perf::pass_over_rest(base, "missing")));
  EXPECT_TRUE(std::isnan(perf::pass_over_rest({{"a", 1.0}}, "a")));
}

// A pass judged in several entries gets one more quantity with all their pairs; a pass judged in
// one entry, and the entries' other quantities, do not.
TEST(AbCompare, PooledPassQuantityHoldsEveryEntrysPairs) {
  auto q = [](const std::string& scene, const std::string& metric, double ratio) {
    perf::AbQuantity x;
    x.scene = scene;
    x.technique = "baseline";
    x.level_name = "lowest";
    x.metric = metric;
    for (int i = 0; i < 8; ++i) {
      x.base.push_back(1.0 + 0.01 * i);
      x.candidate.push_back((1.0 + 0.01 * i) * ratio);
    }
    return x;
  };
  const std::vector<perf::AbQuantity> quantities = {q("desk_spot", "pass:shade_direct", 1.1), q("corner", "pass:shade_direct", 1.1),
                                                    q("corner", "pass:recon_positions", 1.0), q("corner", "cpu_ms", 1.0)};
  const auto pooled = perf::pool_pass_quantities(quantities, perf::AbRule{});
  ASSERT_EQ(pooled.size(), 1u);
  EXPECT_EQ(pooled[0].metric, "pass:shade_direct");
  EXPECT_EQ(pooled[0].scene, "every entry");
  EXPECT_EQ(pooled[0].level_name, "2 entries");
  EXPECT_EQ(pooled[0].base.size(), 16u);
  EXPECT_EQ(pooled[0].judgement.pairs, 16u);
  EXPECT_NEAR(pooled[0].judgement.median_ratio, 1.1, 1e-9);
  EXPECT_LT(pooled[0].judgement.p_value, 1e-4);
}
