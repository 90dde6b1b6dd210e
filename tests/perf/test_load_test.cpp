// The scheduler's load test (mrgi/perf/load_test.h) on a short run: every frame comes back with
// the scheduler's choice, the script's phases happen (the technique is skipped while the object
// is out of view, runs again after), the figures are computed over the frames after the start,
// and the report and trace are written. The figures themselves are the bench's business
// (perf/results/scheduler/), not a timed unit test's.
#include <gtest/gtest.h>

#include "mrgi/perf/load_test.h"

namespace {

TEST(LoadTest, ScriptRunsAndFiguresAreComputed) {
  mrgi::perf::LoadTestSettings s;
  s.suite = std::string(MRGI_SOURCE_DIR) + "/perf/suite.json";
  s.scene = "desk_spot";
  s.technique = "baseline";
  s.frames = 90;
  s.settle_frames = 10;
  s.oracle = false;
  auto r = mrgi::perf::run_load_test(s);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->scheduled.size(), 90u);
  ASSERT_EQ(r->phases.size(), 4u);
  for (const mrgi::perf::LoadPhase& p : r->phases) EXPECT_LT(p.from, p.to) << p.what;
  // Out of view: the technique is skipped; before and after, it runs.
  int skipped_out = 0, ran_in = 0;
  for (const mrgi::perf::LoadPhase& p : r->phases) {
    if (p.what != "object out of view") continue;
    for (int k = p.from + 2; k < p.to; ++k) skipped_out += !r->scheduled[size_t(k)].technique_ran;
    for (int k = p.from - 6; k < p.from - 1; ++k) ran_in += r->scheduled[size_t(k)].technique_ran;
    EXPECT_GE(skipped_out, p.to - p.from - 3);
  }
  EXPECT_EQ(ran_in, 5);
  for (const mrgi::perf::LoadFrame& f : r->scheduled) {
    EXPECT_GE(f.level, 0);
    EXPECT_LT(f.level, int(r->level_names.size()));
    EXPECT_GT(f.scale, 0.0f);
    EXPECT_TRUE(f.cost_ms >= 0.0 && f.cost_ms < 1e5);
  }
  EXPECT_GE(r->share_within, 0.0);
  EXPECT_LE(r->share_within, 1.0);
  const std::string md = mrgi::perf::load_test_markdown(*r);
  EXPECT_NE(md.find("frames within the budget"), std::string::npos);
  const mrgi::ImageRGB8 trace = mrgi::perf::render_load_trace(*r);
  EXPECT_EQ(trace.width, 1100);
  // Refused: too short a run, an unknown scene.
  s.frames = 10;
  EXPECT_EQ(mrgi::perf::run_load_test(s).error().kind, mrgi::ErrorKind::BadUsage);
  s.frames = 90;
  s.scene = "no_such_scene";
  EXPECT_FALSE(mrgi::perf::run_load_test(s).ok());
}

}  // namespace
