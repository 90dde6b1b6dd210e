// The bench's pure parts on constructed data: the Pareto front, the regression check and its
// baseline file, the suite manifest reader, percentiles and the plot.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "capture/temp_dir.h"
#include "mrgi/perf/pareto.h"
#include "mrgi/perf/regression.h"
#include "mrgi/perf/report.h"
#include "mrgi/perf/stats.h"
#include "mrgi/perf/suite.h"

using mrgi::testing::TempDir;
using mrgi::testing::write_text;
namespace perf = mrgi::perf;

namespace {

TEST(Pareto, FrontOfConstructedPoints) {
  // (cost, error): 0 and 2 and 4 are non-dominated; 1 is dominated by 0, 3 by 2, 5 by 4.
  const std::vector<perf::ParetoPoint> pts = {{1.0, 0.9}, {1.5, 0.95}, {3.0, 0.5}, {3.5, 0.5}, {6.0, 0.1}, {6.0, 0.2}};
  EXPECT_EQ(perf::pareto_front(pts), (std::vector<size_t>{0, 2, 4}));
}

TEST(Pareto, SortedByCostAndTiesKept) {
  const std::vector<perf::ParetoPoint> pts = {{5.0, 0.1}, {1.0, 0.5}, {1.0, 0.5}, {2.0, 0.6}};
  // Out of input order, sorted by cost; the identical pair both stays; (2, 0.6) is dominated.
  EXPECT_EQ(perf::pareto_front(pts), (std::vector<size_t>{1, 2, 0}));
}

TEST(Pareto, NonFiniteNeverOnFrontNorDominates) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<perf::ParetoPoint> pts = {{0.0, nan}, {2.0, 0.3}, {-std::numeric_limits<double>::infinity(), 0.0}};
  EXPECT_EQ(perf::pareto_front(pts), (std::vector<size_t>{1}));
  EXPECT_TRUE(perf::pareto_front({}).empty());
}

TEST(Stats, PercentileNearestRank) {
  EXPECT_EQ(perf::percentile({}, 50), 0.0);
  EXPECT_EQ(perf::percentile({3, 1, 2}, 50), 2.0);
}

// Unresolved timestamps (0 ms, or a negative or NaN difference) leave the sample before its
// median: the bench's floor pass keeps its ratios instead of dividing by 0.
TEST(Stats, UnresolvedTimesLeaveTheSample) {
  std::vector<double> times{2.0, 0.0, 1.5, -1.0, std::nan(""), 0.0, 3.0};
  EXPECT_EQ(perf::drop_unresolved_times(times), 4u);
  EXPECT_EQ(times, (std::vector<double>{2.0, 1.5, 3.0}));
  EXPECT_EQ(perf::percentile(times, 50), 2.0);
  EXPECT_EQ(perf::percentile({1, 2, 3, 4}, 50), 2.0);
  std::vector<double> v;
  for (int i = 1; i <= 100; ++i) v.push_back(i);
  EXPECT_EQ(perf::percentile(v, 95), 95.0);
  EXPECT_EQ(perf::percentile(v, 100), 100.0);
}

// A result with two scenes x one technique x two levels, as run_bench would return it.
perf::BenchResult constructed_result() {
  perf::BenchResult r;
  r.device = "test device";
  r.lp_num_threads = "2";
  r.frames = 4;
  r.floor_median_ms = 2.0;
  for (const char* scene : {"desk", "empty"}) {
    r.floors.push_back({scene, 64, 48, 10, 2.0, 2.2, 1.9});
    for (int level = 0; level < 2; ++level) {
      perf::BenchEntry e;
      e.scene = scene;
      e.technique = "baseline";
      e.level = level;
      e.level_name = level == 0 ? "high" : "low";
      e.width = 64;
      e.height = 48;
      e.frame = {4, 20.0 - 10.0 * level, 22.0, 10.0 - 5.0 * level, 11.0};
      e.sustained_ms = e.frame.median_ms;
      e.sustained_ratio = e.frame.median_ratio;
      e.profiled = e.frame;
      e.has_reference = true;
      e.error.all.pixels = 64 * 48;
      e.error.all.delta_rms = 0.004;
      if (std::string(scene) == "desk") {
        e.error.all.rde_defined = true;
        e.error.all.rde = 0.3 + 0.2 * level;
        e.error.all.err2 = e.error.all.rde * e.error.all.rde;
        e.error.all.ref2 = 1.0;
      }
      e.passes.push_back({"shade", {4, 5.0, 6.0, 2.5, 3.0}});
      r.entries.push_back(e);
    }
  }
  return r;
}

TEST(Regression, PassesAgainstItself) {
  const perf::BenchResult r = constructed_result();
  const perf::CheckReport rep = perf::check_against(r, perf::make_baseline(r));
  EXPECT_TRUE(rep.passed) << rep.summary();
  EXPECT_EQ(rep.compared, 4u);
  EXPECT_TRUE(rep.violations.empty());
  EXPECT_TRUE(rep.missing_in_run.empty());
  EXPECT_TRUE(rep.missing_in_baseline.empty());
}

// junit.xml: one test case per entry, the finding a <failure> of the entry it names; a clean
// check has no failure.
TEST(Regression, JunitXmlPutsEachFindingOnItsEntry) {
  const perf::BenchResult r = constructed_result();
  perf::Baseline b = perf::make_baseline(r);
  const std::string clean = perf::junit_xml(r, perf::check_against(r, b));
  EXPECT_NE(clean.find("<testsuites name=\"mrgi bench --check\" tests=\"6\" failures=\"0\">"), std::string::npos) << clean;
  EXPECT_EQ(clean.find("<failure"), std::string::npos);
  b.entries[1].ratio_to_floor /= 2.0;
  const std::string xml = perf::junit_xml(r, perf::check_against(r, b));
  EXPECT_NE(xml.find("failures=\"1\""), std::string::npos) << xml;
  const size_t c = xml.find("name=\"desk/baseline/low\">");
  ASSERT_NE(c, std::string::npos) << xml;
  const size_t f = xml.find("<failure message=\"desk/baseline/low: sustained frame time ratio", c);
  EXPECT_NE(f, std::string::npos) << xml;
  EXPECT_LT(f, xml.find("</testcase>", c));
  EXPECT_NE(xml.find("name=\"desk/baseline/high\"/>"), std::string::npos) << xml;
}

TEST(Regression, RatioGrowthBeyondToleranceFails) {
  const perf::BenchResult r = constructed_result();
  perf::Baseline b = perf::make_baseline(r);
  b.entries[1].ratio_to_floor /= 2.0;  // the run is now 100 % slower than the baseline
  perf::CheckReport rep = perf::check_against(r, b);
  EXPECT_FALSE(rep.passed);
  ASSERT_EQ(rep.violations.size(), 1u) << rep.summary();
  EXPECT_NE(rep.violations[0].find("desk/baseline/low"), std::string::npos) << rep.violations[0];
  EXPECT_NE(rep.violations[0].find("ratio"), std::string::npos) << rep.violations[0];
  // Within tolerance (run 30 % slower than the baseline, limit 35 %) passes.
  b = perf::make_baseline(r);
  b.tolerances.ratio_absolute = 0.0;
  b.entries[1].ratio_to_floor /= 1.30;
  EXPECT_TRUE(perf::check_against(r, b).passed);
  b.entries[1].ratio_to_floor = r.entries[1].sustained_ratio / 1.40;
  EXPECT_FALSE(perf::check_against(r, b).passed);
  // The absolute slack (1 floor pass by default): 5.0 <= 3.57 x 1.35 + 1 = 5.82.
  b.tolerances.ratio_absolute = 1.0;
  EXPECT_TRUE(perf::check_against(r, b).passed);
}

// The per-pass rule: a checked pass's median change over the run's entries, relative to the
// run's median change, fails above 1 + pass_ratio_relative; a slowdown of the whole run (machine
// load) moves every pass together and fails nothing; passes under pass_min_share are not checked.
TEST(Regression, OnePassTwentyPercentSlowerFailsAWholeSlowerRunDoesNot) {
  perf::BenchResult r = constructed_result();
  for (perf::BenchEntry& e : r.entries) {
    e.profiled = {4, 10.0, 11.0, 5.0, 5.5, 10.0, 5.0};              // min ratio 5 for the frame
    e.passes = {{"shade", {4, 6.0, 6.5, 3.0, 3.2, 6.0, 3.0}},       // 60 % of the frame
                {"shadow", {4, 3.0, 3.5, 1.5, 1.6, 3.0, 1.5}},      // 30 %
                {"recon", {4, 3.0, 3.5, 1.5, 1.6, 3.0, 1.5}},       // 30 %
                {"tiny", {4, 0.2, 0.3, 0.1, 0.15, 0.2, 0.1}}};      // 2 %: not checked
  }
  const perf::Baseline b = perf::make_baseline(r);
  ASSERT_EQ(b.entries[0].pass_ratios.size(), 4u);
  EXPECT_TRUE(perf::check_against(r, b).passed);
  perf::BenchResult slow = r;
  for (perf::BenchEntry& e : slow.entries) {
    e.passes[0].time.min_ratio *= 1.20;  // planted: +20 % on one pass
    e.passes[3].time.min_ratio *= 3.0;   // a tiny pass: ignored
  }
  const perf::CheckReport rep = perf::check_against(slow, b);
  EXPECT_FALSE(rep.passed);
  ASSERT_EQ(rep.violations.size(), 1u) << rep.summary();
  EXPECT_NE(rep.violations[0].find("pass shade"), std::string::npos) << rep.violations[0];
  perf::BenchResult loaded = r;  // the machine 30 % slower for every pass: no pass regressed
  for (perf::BenchEntry& e : loaded.entries)
    for (perf::PassSummary& p : e.passes) p.time.min_ratio *= 1.30;
  EXPECT_TRUE(perf::check_against(loaded, b).passed) << perf::check_against(loaded, b).summary();
  perf::BenchResult noisy = r;
  for (perf::BenchEntry& e : noisy.entries) e.passes[0].time.min_ratio *= 1.05;  // within 7.5 %
  EXPECT_TRUE(perf::check_against(noisy, b).passed);
}

TEST(Regression, PassRatiosRoundTripThroughTheFile) {
  perf::BenchResult r = constructed_result();
  r.entries[0].profiled = {4, 10.0, 11.0, 5.0, 5.5, 10.0, 5.0};
  r.entries[0].passes[0].time.min_ratio = 2.5;
  const perf::Baseline b = perf::make_baseline(r);
  TempDir dir;
  ASSERT_TRUE(perf::write_baseline(dir.file("b.json"), b).ok());
  auto back = perf::load_baseline(dir.file("b.json"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->entries[0].pass_ratios.size(), 1u);
  EXPECT_EQ(back->entries[0].pass_ratios[0].first, "shade");
  EXPECT_DOUBLE_EQ(back->entries[0].pass_ratios[0].second, 2.5);
  EXPECT_DOUBLE_EQ(back->entries[0].profiled_ratio, 5.0);
  EXPECT_DOUBLE_EQ(back->tolerances.pass_ratio_relative, 0.075);
}

TEST(Regression, DifferentFrameCountsAreNotCompared) {
  perf::BenchResult r = constructed_result();
  const perf::Baseline b = perf::make_baseline(r);
  r.warmup = b.warmup + 3;
  perf::CheckReport rep = perf::check_against(r, b);
  EXPECT_FALSE(rep.passed);
  ASSERT_EQ(rep.violations.size(), 1u) << rep.summary();
  EXPECT_NE(rep.violations[0].find("not comparable"), std::string::npos) << rep.violations[0];
  EXPECT_NE(rep.violations[0].find("--frames 4 --warmup"), std::string::npos) << rep.violations[0];
  r = constructed_result();
  r.frames = 16;
  EXPECT_FALSE(perf::check_against(r, b).passed);
}

TEST(Regression, RdeGrowthBeyondToleranceFails) {
  const perf::BenchResult r = constructed_result();
  perf::Baseline b = perf::make_baseline(r);
  *b.entries[0].rde -= 0.05;  // the run's RDE is now 0.05 above the baseline (tolerance 0.02)
  perf::CheckReport rep = perf::check_against(r, b);
  EXPECT_FALSE(rep.passed);
  ASSERT_EQ(rep.violations.size(), 1u) << rep.summary();
  EXPECT_NE(rep.violations[0].find("desk/baseline/high: RDE"), std::string::npos) << rep.violations[0];
  b = perf::make_baseline(r);
  *b.entries[0].rde -= 0.015;
  EXPECT_TRUE(perf::check_against(r, b).passed);
  // Both violations are listed, not just the first.
  b = perf::make_baseline(r);
  *b.entries[0].rde -= 0.05;
  b.entries[3].ratio_to_floor /= 2.0;
  EXPECT_EQ(perf::check_against(r, b).violations.size(), 2u);
}

TEST(Regression, UndefinedRdeComparesDeltaRms) {
  const perf::BenchResult r = constructed_result();
  perf::Baseline b = perf::make_baseline(r);
  ASSERT_FALSE(b.entries[2].rde.has_value());  // scene "empty": nothing should change
  ASSERT_TRUE(b.entries[2].delta_rms.has_value());
  *b.entries[2].delta_rms = 0.004 - 0.02;  // run's delta RMS is 0.02 above, tolerance 0.01
  const perf::CheckReport rep = perf::check_against(r, b);
  ASSERT_EQ(rep.violations.size(), 1u) << rep.summary();
  EXPECT_NE(rep.violations[0].find("empty/baseline/high: delta RMS"), std::string::npos) << rep.violations[0];
}

TEST(Regression, MissingEntriesReported) {
  perf::BenchResult r = constructed_result();
  perf::Baseline b = perf::make_baseline(r);
  b.entries.push_back({"desk", "dir", "high", 0, 4.0, 0.2, 0.01});
  r.entries.push_back(r.entries[0]);
  r.entries.back().technique = "ssrt";
  perf::CheckReport rep = perf::check_against(r, b);
  EXPECT_EQ(rep.missing_in_run, (std::vector<std::string>{"desk/dir/high"}));
  EXPECT_EQ(rep.missing_in_baseline, (std::vector<std::string>{"desk/ssrt/high"}));
  EXPECT_FALSE(rep.passed) << "a full run that lacks a baseline entry must fail";
  r.subset = true;
  rep = perf::check_against(r, b);
  EXPECT_TRUE(rep.passed) << "a restricted run is not blamed for what it did not run: " << rep.summary();
  // Nothing in common: nothing compared is a failure even for a subset.
  perf::Baseline other;
  other.entries.push_back({"x", "y", "z", 0, 1.0, 0.1, 0.1});
  EXPECT_FALSE(perf::check_against(r, other).passed);
}

TEST(Regression, BaselineFileRoundTripAndRefusals) {
  TempDir dir;
  const perf::BenchResult r = constructed_result();
  perf::Tolerances tol;
  tol.ratio_relative = 0.5;
  ASSERT_TRUE(perf::write_baseline(dir.file("b.json"), perf::make_baseline(r, tol)).ok());
  auto b = perf::load_baseline(dir.file("b.json"));
  ASSERT_TRUE(b.ok()) << b.error().message;
  EXPECT_EQ(b->tolerances.ratio_relative, 0.5);
  ASSERT_EQ(b->entries.size(), 4u);
  EXPECT_EQ(b->entries[1].level_name, "low");
  EXPECT_DOUBLE_EQ(b->entries[1].ratio_to_floor, 5.0);
  EXPECT_FALSE(b->entries[2].rde.has_value());
  EXPECT_TRUE(perf::check_against(r, *b).passed);

  EXPECT_ERROR(perf::load_baseline(dir.file("none.json")), NotFound, "none.json");
  write_text(dir.file("bad.json"), "{\"version\": 1, ");
  EXPECT_ERROR(perf::load_baseline(dir.file("bad.json")), BadInput, "bad.json", "not valid JSON");
  write_text(dir.file("v2.json"), R"({"version": 2, "tolerances": {}, "entries": []})");
  EXPECT_ERROR(perf::load_baseline(dir.file("v2.json")), BadInput, "\"version\" must be 1");
  write_text(dir.file("tol.json"),
             R"({"version": 1, "tolerances": {"ratio_relative": -1, "rde_absolute": 0.02, "delta_rms_absolute": 0.01}, "entries": []})");
  EXPECT_ERROR(perf::load_baseline(dir.file("tol.json")), BadInput, "tolerances.ratio_relative", ">= 0");
  const std::string tol_ok = R"("tolerances": {"ratio_relative": 0.35, "rde_absolute": 0.02, "delta_rms_absolute": 0.01})";
  write_text(dir.file("ratio.json"), R"({"version": 1, )" + tol_ok +
                                         R"(, "entries": [{"scene": "a", "technique": "b", "level": 0, "level_name": "c", "ratio_to_floor": "x", "rde": null, "delta_rms": null}]})");
  EXPECT_ERROR(perf::load_baseline(dir.file("ratio.json")), BadInput, "entries[0].ratio_to_floor", "number");
  const std::string e = R"({"scene": "a", "technique": "b", "level": 0, "level_name": "c", "ratio_to_floor": 2, "rde": 0.1, "delta_rms": null})";
  write_text(dir.file("dup.json"), R"({"version": 1, )" + tol_ok + R"(, "entries": [)" + e + "," + e + "]}");
  EXPECT_ERROR(perf::load_baseline(dir.file("dup.json")), BadInput, "entries[1]", "a/b/c appears twice");
}

TEST(Suite, ReadsScenesAndResolvesPaths) {
  TempDir dir;
  write_text(dir.file("perf/suite.json"),
             R"({"scenes": [{"name": "desk", "capture": "perf/suite/desk", "description": "d", "effect": "shadow"},
                            {"name": "abs", "capture": "/data/x"}]})");
  auto s = perf::load_suite(dir.file("perf/suite.json"));
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_EQ(s->size(), 2u);
  EXPECT_EQ((*s)[0].capture, dir.file("perf/suite/desk"));  // relative to the repo root
  EXPECT_EQ((*s)[0].effect, "shadow");
  EXPECT_EQ((*s)[1].capture, "/data/x");
  auto one = perf::select_scenes(*s, {"abs"});
  ASSERT_TRUE(one.ok());
  ASSERT_EQ(one->size(), 1u);
  EXPECT_EQ((*one)[0].name, "abs");
  EXPECT_ERROR(perf::select_scenes(*s, {"nope"}), BadUsage, "no scene 'nope'", "desk, abs");
}

TEST(Suite, Refusals) {
  TempDir dir;
  EXPECT_ERROR(perf::load_suite(dir.file("missing.json")), NotFound, "missing.json");
  write_text(dir.file("a.json"), R"({"scenes": [{"capture": "x"}]})");
  EXPECT_ERROR(perf::load_suite(dir.file("a.json")), BadInput, "scenes[0]", "\"name\"");
  write_text(dir.file("b.json"), R"({"scenes": [{"name": "a b", "capture": "x"}]})");
  EXPECT_ERROR(perf::load_suite(dir.file("b.json")), BadInput, "scenes[0].name", "'a b'");
  write_text(dir.file("c.json"), R"({"scenes": [{"name": "a", "capture": "x"}, {"name": "a", "capture": "y"}]})");
  EXPECT_ERROR(perf::load_suite(dir.file("c.json")), BadInput, "scenes[1].name", "twice");
  write_text(dir.file("d.json"), R"({"scenes": []})");
  EXPECT_ERROR(perf::load_suite(dir.file("d.json")), BadInput, "no scenes");
  write_text(dir.file("e.json"), R"({"scenes": [{"name": "a", "capture": 3}]})");
  EXPECT_ERROR(perf::load_suite(dir.file("e.json")), BadInput, "scenes[0].capture", "string");
}

// Several manifests read as one run: scenes in order, each with its set's name; a name two
// manifests share is refused naming both files.
TEST(Suite, SeveralManifestsAsOneRun) {
  TempDir dir;
  write_text(dir.file("perf/suite.json"), R"({"scenes": [{"name": "desk", "capture": "perf/suite/desk"}]})");
  write_text(dir.file("perf/cycles-heldout.json"), R"({"scenes": [{"name": "sky", "capture": "perf/cycles/sky"}]})");
  auto s = perf::load_suites(dir.file("perf/suite.json") + "," + dir.file("perf/cycles-heldout.json"));
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_EQ(s->size(), 2u);
  EXPECT_EQ((*s)[0].set, "suite");
  EXPECT_EQ((*s)[1].name, "sky");
  EXPECT_EQ((*s)[1].set, "cycles-heldout");
  EXPECT_EQ((*s)[1].capture, dir.file("perf/cycles/sky"));
  write_text(dir.file("perf/again.json"), R"({"scenes": [{"name": "desk", "capture": "x"}]})");
  EXPECT_ERROR(perf::load_suites(dir.file("perf/suite.json") + "," + dir.file("perf/again.json")), BadInput,
               "'desk'", "suite.json");
  EXPECT_ERROR(perf::load_suites(dir.file("perf/suite.json") + ","), BadUsage, "empty manifest path");
}

// With more than one set, the report gives each set's median RDE apart; with one, no such table.
TEST(Report, AccuracyBySetWhenSeveralSets) {
  perf::BenchResult r = constructed_result();
  EXPECT_EQ(perf::report_markdown(r, nullptr).find("Accuracy by scene set"), std::string::npos);
  for (perf::BenchEntry& e : r.entries) e.set = e.scene == "desk" ? "suite" : "cycles-heldout";
  const std::string md = perf::report_markdown(r, nullptr);
  EXPECT_NE(md.find("## Accuracy by scene set"), std::string::npos);
  // desk (suite): RDE 0.3 at high, 0.5 at low, the worst of its set; empty has no defined RDE.
  EXPECT_NE(md.find("| suite | baseline | 0 high | 1 | 0.300 | - | - | desk 0.300 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| suite | baseline | 1 low | 1 | 0.500 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| cycles-heldout | baseline | 0 high | 0 | - | - | - | - |"), std::string::npos) << md;
  // Two scenes in a set: the median is the mean of the middle two (0.3 and 0.7 at high).
  perf::BenchEntry other = r.entries.front();
  for (perf::BenchEntry& e : r.entries) {
    e.set = "suite";
    if (e.scene == "empty") {
      e.error.all.rde_defined = true;
      e.error.all.rde = 0.7;
    }
  }
  other.scene = "sky";
  other.set = "cycles-heldout";
  r.entries.push_back(other);
  EXPECT_NE(perf::report_markdown(r, nullptr).find("| suite | baseline | 0 high | 2 | 0.500 |"), std::string::npos);
}

TEST(Plot, DrawsSeriesFrontAndAxes) {
  perf::BenchResult r = constructed_result();
  const mrgi::ImageRGB8 img = perf::render_pareto_plot(r);
  ASSERT_EQ(img.width, 1640);
  ASSERT_EQ(img.height, 600);
  // The first technique's colour (31, 119, 180) appears (its markers, in the all, real and
  // virtual panels), and so does black (axes,
  // text); most of the picture stays white.
  size_t blue = 0, black = 0, white = 0;
  for (size_t i = 0; i < img.pixel_count(); ++i) {
    const uint8_t* p = &img.data[i * 3];
    blue += p[0] == 31 && p[1] == 119 && p[2] == 180;
    black += p[0] == 0 && p[1] == 0 && p[2] == 0;
    white += p[0] == 255 && p[1] == 255 && p[2] == 255;
  }
  EXPECT_GT(blue, 40u);
  EXPECT_GT(black, 2000u);
  EXPECT_GT(white, img.pixel_count() / 2);
  // Without any defined RDE no marker is drawn.
  for (auto& e : r.entries) e.has_reference = false;
  const mrgi::ImageRGB8 empty = perf::render_pareto_plot(r);
  size_t blue2 = 0;
  for (size_t i = 0; i < empty.pixel_count(); ++i)
    blue2 += empty.data[i * 3] == 31 && empty.data[i * 3 + 1] == 119 && empty.data[i * 3 + 2] == 180;
  // Only the legend's marker is left: the two data markers (radius 6 px) are gone.
  EXPECT_GT(blue, blue2 + 100) << blue << " vs " << blue2;
  EXPECT_LT(blue2, 100u);
}

// passes.png: each level's bar is its passes stacked on the bar's own scale, the larger of its
// passes' sum and its sustained frame (shade: 5 ms at every level; the levels' frames are 20 and
// 10 ms, so shade fills a quarter of the first bar and half of the second), with a black tick at
// the sustained frame, here the bar's full width.
TEST(Plot, PassBarsAreToScale) {
  perf::BenchResult r = constructed_result();
  for (perf::BenchEntry& e : r.entries) e.passes.push_back({"compose", {4, 2.0 + e.level, 3.0, 1.0, 1.0}});
  const mrgi::ImageRGB8 img = perf::render_pass_plot(r);
  ASSERT_EQ(img.width, 1480);
  const int px0 = 210, px1 = 1480 - 520;  // the bars' area
  // Row through the middle of each bar: count the first colour (the costliest pass: shade,
  // 5 ms) and the second (compose: 2 ms, then 3 ms).
  auto count_row = [&](int y, uint8_t r0, uint8_t g0, uint8_t b0) {
    int n = 0;
    for (int x = 0; x < px1; ++x) n += img.at(x, y)[0] == r0 && img.at(x, y)[1] == g0 && img.at(x, y)[2] == b0;
    return n;
  };
  // Bars start at y = 70 + 10, 22 px high, 32 px apart.
  const int y0 = 70 + 10 + 11, y1 = y0 + 32;
  const int shade0 = count_row(y0, 31, 119, 180), shade1 = count_row(y1, 31, 119, 180);
  const int compose0 = count_row(y0, 255, 127, 14), compose1 = count_row(y1, 255, 127, 14);
  EXPECT_NEAR(shade0, (px1 - px0) * 5.0 / 20.0, 4) << "5 ms of a 20 ms frame";
  EXPECT_NEAR(shade1, (px1 - px0) * 5.0 / 10.0, 4) << "5 ms of a 10 ms frame";
  EXPECT_NEAR(double(compose0) / shade0, 2.0 / 5.0, 0.05);
  EXPECT_NEAR(double(compose1) / shade1, 3.0 / 5.0, 0.05);
  // The sustained tick of each bar lies at its right end.
  for (int y : {y0 - 13, y1 - 13}) {
    int tick_x = -1;
    for (int x = px1 + 3; x > px0; --x)
      if (img.at(x, y)[0] == 0 && img.at(x, y)[1] == 0 && img.at(x, y)[2] == 0) {
        tick_x = x;
        break;
      }
    EXPECT_NEAR(tick_x, px1, 3) << "row " << y;
  }
}

TEST(Report, CsvAndMarkdownHoldEveryEntry) {
  const perf::BenchResult r = constructed_result();
  const std::string csv = perf::bench_csv(r);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);  // header + 4 rows
  EXPECT_NE(csv.find("pass_shade_median_ms"), std::string::npos);
  // sustained ms, its ratio, the p95 interval, the profiled frame's median.
  EXPECT_NE(csv.find("desk,baseline,1,low,64,48,4,10.0000,5.0000,22.0000,10.0000"), std::string::npos) << csv;
  const std::string md = perf::report_markdown(r, nullptr);
  EXPECT_NE(md.find("## baseline"), std::string::npos);
  EXPECT_NE(md.find("pareto.png"), std::string::npos);
  EXPECT_NE(md.find("| desk | 1 low | 10.00 | 22.00 | 5.0 |"), std::string::npos) << md;
  // Suite aggregate: level "low" is faster (mean 10 ms) and level "high" more accurate: both on the front.
  const nlohmann::json j = perf::bench_json(r, nullptr);
  ASSERT_EQ(j["suite_aggregate"].size(), 2u);
  EXPECT_TRUE(j["suite_aggregate"][0]["pareto"].get<bool>());
  EXPECT_TRUE(j["suite_aggregate"][1]["pareto"].get<bool>());
  EXPECT_DOUBLE_EQ(j["suite_aggregate"][1]["mean_sustained_ms"].get<double>(), 10.0);
  // Temporal stability: "-" where not measured; output / truth x 1000 where it is.
  EXPECT_NE(md.find("| SSIM | flicker |"), std::string::npos);
  perf::BenchResult with = r;
  with.entries[0].stability_pairs = 3;
  with.entries[0].stability = 0.003;
  with.entries[0].truth_stability = 0.009;
  EXPECT_NE(perf::report_markdown(with, nullptr).find(" | 3.00 / 9.00 |"), std::string::npos);
  EXPECT_EQ(perf::bench_json(with, nullptr)["entries"][0]["stability"]["pairs"].get<size_t>(), 3u);
  EXPECT_TRUE(perf::bench_json(r, nullptr)["entries"][0]["stability"]["output"].is_null());
}

}  // namespace
