// The bench end to end on a suite subset (the first scene of perf/suite.json, the `baseline`
// technique at its best and cheapest level, a few frames) through the library API: the four
// files exist and parse, the regression check passes against the run's own baseline and fails
// on a doctored one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "capture/temp_dir.h"
#include "mrgi/image.h"
#include "mrgi/perf/bench.h"
#include "mrgi/perf/regression.h"
#include "mrgi/perf/report.h"
#include "mrgi/perf/sample_sheet.h"
#include "mrgi/perf/suite.h"

using mrgi::testing::TempDir;
namespace fs = std::filesystem;
namespace perf = mrgi::perf;

namespace {

// MRGI_PERF_TEST_SUITE points the subset at another suite file (e.g. while a suite is rebuilt).
const std::string kSuite = std::getenv("MRGI_PERF_TEST_SUITE") ? std::getenv("MRGI_PERF_TEST_SUITE")
                                                                : std::string(MRGI_SOURCE_DIR) + "/perf/suite.json";

// One bench run for the checks below (CTest runs each TEST in a process of its own, so they are
// one TEST: the run takes seconds to a minute on lavapipe).
perf::BenchResult run_subset() {
  perf::BenchResult result = [] {
    auto suite = perf::load_suite(kSuite);
    EXPECT_TRUE(suite.ok()) << suite.error().message;
    if (!suite.ok()) return perf::BenchResult{};
    perf::BenchSettings s;
    s.suite = kSuite;
    s.scenes = {(*suite)[0].name};
    s.techniques = {"baseline"};
    s.levels = {"0", "last"};
    s.frames = 3;
    s.warmup = 1;
    s.profile_frames = 2;
    s.floor_frames = 5;
    s.floor_warmup = 1;
    auto r = perf::run_bench(s);
    EXPECT_TRUE(r.ok()) << r.error().message;
    return r.ok() ? std::move(r).value() : perf::BenchResult{};
  }();
  return result;
}

void check_measures(const perf::BenchResult& r) {
  ASSERT_FALSE(r.entries.empty());
  EXPECT_EQ(r.lp_num_threads, "2");  // set by the bench when unset; CTest does not set it
  EXPECT_TRUE(r.subset);
  ASSERT_EQ(r.floors.size(), 1u);
  EXPECT_GT(r.floors[0].median_ms, 0.0);
  EXPECT_GE(r.floors[0].samples, 5u);
  EXPECT_GT(r.floor_median_ms, 0.0);
  auto levels = mrgi::technique_levels("baseline");
  ASSERT_TRUE(levels.ok());
  EXPECT_EQ(r.entries.size(), levels->size() > 1 ? 2u : 1u);
  for (const perf::BenchEntry& e : r.entries) {
    EXPECT_EQ(e.technique, "baseline");
    // Sustained: one completion interval per measured frame (the first from the last warm-up
    // frame), and the headline is their mean.
    EXPECT_EQ(e.frame.samples, 3u);
    EXPECT_GT(e.frame.median_ms, 0.0);
    EXPECT_GE(e.frame.p95_ms, e.frame.median_ms);
    EXPECT_GT(e.sustained_ms, 0.0);
    EXPECT_NEAR(e.sustained_ratio, e.sustained_ms / r.floors[0].median_ms, 1e-9);
    // Profiling phase: its passes add up to its frame (the split is the frame, by construction).
    EXPECT_EQ(e.profiled.samples, 2u);
    EXPECT_FALSE(e.passes.empty());
    double pass_sum = 0.0;
    for (const auto& p : e.passes) {
      EXPECT_EQ(p.time.samples, 2u) << p.name;
      EXPECT_LE(p.time.median_ms, e.profiled.p95_ms * 1.0001) << p.name;
      pass_sum += p.time.median_ms;
    }
    EXPECT_GT(pass_sum, 0.5 * e.profiled.median_ms);
    EXPECT_LT(pass_sum, 2.0 * e.profiled.p95_ms);
    EXPECT_GT(e.memory_mib, 0.0);
    if (e.has_reference) {
      EXPECT_TRUE(std::isfinite(e.error.all.rde));
      EXPECT_GT(e.error.all.ssim, 0.0);
    }
  }
  EXPECT_EQ(r.entries.front().level, 0);
  EXPECT_EQ(r.entries.back().level, int(levels->size()) - 1);
}

void check_outputs(const perf::BenchResult& r) {
  ASSERT_FALSE(r.entries.empty());
  TempDir dir;
  const std::string out = dir.file("bench");
  const perf::CheckReport check = perf::check_against(r, perf::make_baseline(r));
  ASSERT_TRUE(perf::write_bench_outputs(out, r, &check).ok());
  EXPECT_FALSE(fs::exists(out + ".partial"));
  std::ifstream jf(out + "/bench.json");
  const nlohmann::json j = nlohmann::json::parse(jf);  // throws (fails the test) when malformed
  EXPECT_EQ(j["entries"].size(), r.entries.size());
  EXPECT_EQ(j["lp_num_threads"], "2");
  EXPECT_TRUE(j["check"]["passed"].get<bool>());
  EXPECT_GT(j["floor_median_ms"].get<double>(), 0.0);
  EXPECT_TRUE(j["entries"][0]["passes"].is_array());
  std::ifstream cf(out + "/bench.csv");
  std::string line;
  size_t rows = 0;
  std::getline(cf, line);
  const size_t columns = size_t(std::count(line.begin(), line.end(), ',')) + 1;
  while (std::getline(cf, line)) {
    ++rows;
    EXPECT_EQ(size_t(std::count(line.begin(), line.end(), ',')) + 1, columns) << line;
  }
  EXPECT_EQ(rows, r.entries.size());
  std::ifstream mf(out + "/report.md");
  const std::string md((std::istreambuf_iterator<char>(mf)), std::istreambuf_iterator<char>());
  EXPECT_NE(md.find("## baseline"), std::string::npos);
  EXPECT_NE(md.find("regression check PASSED"), std::string::npos);
  // The check as JUnit XML beside the report, and the pass chart.
  std::ifstream junit_file(out + "/junit.xml");
  const std::string junit((std::istreambuf_iterator<char>(junit_file)), std::istreambuf_iterator<char>());
  EXPECT_NE(junit.find("<testsuite name=\"mrgi.bench.regression\""), std::string::npos) << junit;
  EXPECT_TRUE(fs::exists(out + "/passes.png"));
  auto png = mrgi::load_png_rgb8(out + "/pareto.png");
  ASSERT_TRUE(png.ok()) << png.error().message;
  EXPECT_EQ(png->width, 1640);
  EXPECT_TRUE(fs::exists(out + "/passes.md"));
  // The side-by-side images: the scene's sampled frame from each level, linked from the report.
  const perf::BenchEntry& first = r.entries.front();
  if (first.has_reference) {
    EXPECT_GE(first.sample_frame, 0);
    EXPECT_EQ(first.sample.width, perf::kSampleWidth);
    auto sheet = mrgi::load_png_rgb8(out + "/" + perf::sample_sheet_path(first.scene));
    ASSERT_TRUE(sheet.ok()) << sheet.error().message;
    EXPECT_GE(sheet->width, 2 * perf::kSampleWidth);
    EXPECT_NE(md.find("(" + perf::sample_sheet_path(first.scene) + ")"), std::string::npos);
  }
  // A second write replaces the earlier bench output; a folder that is not one is refused.
  EXPECT_TRUE(perf::write_bench_outputs(out, r, nullptr).ok());
  mrgi::testing::write_text(dir.file("precious/data.txt"), "x");
  EXPECT_ERROR(perf::write_bench_outputs(dir.file("precious"), r, nullptr), BadUsage, "refusing to replace");
  EXPECT_TRUE(fs::exists(dir.file("precious/data.txt")));
}

void check_regression(const perf::BenchResult& r) {
  ASSERT_FALSE(r.entries.empty());
  TempDir dir;
  ASSERT_TRUE(perf::write_baseline(dir.file("baseline.json"), perf::make_baseline(r)).ok());
  auto b = perf::load_baseline(dir.file("baseline.json"));
  ASSERT_TRUE(b.ok()) << b.error().message;
  const perf::CheckReport same = perf::check_against(r, *b);
  EXPECT_TRUE(same.passed) << same.summary();
  EXPECT_EQ(same.compared, r.entries.size());

  perf::Baseline doctored = *b;
  doctored.entries[0].ratio_to_floor /= 2.0;
  perf::CheckReport rep = perf::check_against(r, doctored);
  EXPECT_FALSE(rep.passed);
  ASSERT_EQ(rep.violations.size(), 1u) << rep.summary();
  EXPECT_NE(rep.violations[0].find("ratio"), std::string::npos);

  doctored = *b;
  bool lowered = false;
  for (auto& e : doctored.entries)
    if (e.rde) {
      *e.rde = std::max(0.0, *e.rde - 0.1);
      lowered = true;
    } else if (e.delta_rms) {
      *e.delta_rms = *e.delta_rms - 0.1;  // below zero: any output change now exceeds it
      lowered = true;
    }
  ASSERT_TRUE(lowered) << "the subset scene has no reference frames";
  rep = perf::check_against(r, doctored);
  EXPECT_FALSE(rep.passed) << rep.summary();
  EXPECT_EQ(rep.violations.size(), r.entries.size()) << rep.summary();
}

TEST(BenchSubset, EndToEnd) {
  const perf::BenchResult r = run_subset();
  {
    SCOPED_TRACE("measures");
    check_measures(r);
  }
  {
    SCOPED_TRACE("outputs");
    check_outputs(r);
  }
  {
    SCOPED_TRACE("regression check");
    check_regression(r);
  }
}

TEST(BenchSubset, BadSettingsAreRefused) {
  perf::BenchSettings s;
  s.suite = kSuite;
  s.frames = 0;
  EXPECT_ERROR(perf::run_bench(s), BadUsage, "--frames");
  s.frames = 1;
  s.techniques = {"no-such-technique"};
  EXPECT_ERROR(perf::run_bench(s), BadUsage, "unknown technique 'no-such-technique'");
  s.techniques = {"baseline"};
  s.levels = {"99"};
  EXPECT_ERROR(perf::run_bench(s), BadUsage, "--levels '99'", "technique 'baseline' has levels");
  s.levels = {};
  s.scenes = {"no-such-scene"};
  EXPECT_ERROR(perf::run_bench(s), BadUsage, "no scene 'no-such-scene'");
}

}  // namespace
