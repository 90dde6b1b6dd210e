// `mrgi peaks` (perf/include/mrgi/perf/peaks.h) with small kernels: every rate is measured,
// positive and finite, the floor pass is beside them, and bad settings are refused.
#include <gtest/gtest.h>

#include <cmath>

#include "mrgi/perf/peaks.h"

namespace {

TEST(Peaks, SmallKernelsGiveFiniteRatesBesideTheFloorPass) {
  mrgi::perf::PeaksSettings s;
  s.repeats = 2;
  s.fma_invocations = 4096;
  s.fma_iterations = 16;
  s.copy_mib = 4;
  s.image_loads = 2;
  auto p = mrgi::perf::measure_peaks(s);
  ASSERT_TRUE(p.ok()) << p.error().message;
  EXPECT_GT(p->floor_median_ms, 0.0);
  ASSERT_EQ(p->results.size(), 5u);
  const char* names[] = {"fma", "copy", "image_load", "buffer_gather", "buffer_floor"};
  for (size_t i = 0; i < 5; ++i) {
    const auto& r = p->results[i];
    EXPECT_EQ(r.name, names[i]);
    EXPECT_TRUE(std::isfinite(r.rate) && r.rate > 0.0) << r.name;
    EXPECT_GE(r.best_rate, r.rate) << r.name;
    EXPECT_GT(r.work, 0.0);
  }
  const std::string md = mrgi::perf::peaks_markdown(*p);
  EXPECT_NE(md.find("GFLOP/s"), std::string::npos);
  EXPECT_NE(md.find("floor pass"), std::string::npos);
}

TEST(Peaks, BadSettingsAreRefused) {
  mrgi::perf::PeaksSettings s;
  s.repeats = 0;
  auto p = mrgi::perf::measure_peaks(s);
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().kind, mrgi::ErrorKind::BadUsage);
}

}  // namespace
