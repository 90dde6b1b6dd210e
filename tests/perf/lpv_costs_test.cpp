// mrgi lpv-costs (perf/include/mrgi/perf/lpv_costs.h): a tiny run gives a row per entry and the
// paper's columns where the paper has the entry; bad sizes are refused by name.
#include <gtest/gtest.h>

#include "mrgi/perf/lpv_costs.h"

namespace {
using namespace mrgi;

TEST(LpvCosts, SmallRunHasEveryEntryAndThePapersColumns) {
  perf::LpvCostSettings s;
  s.device.device = "llvmpipe";
  s.volume_sizes = {8, 16};
  s.steps = {2, 16};
  s.rsm_sizes = {16, 256};
  s.repeats = 1;
  auto c = perf::measure_lpv_costs(s);
  ASSERT_TRUE(c.ok()) << c.error().message;
  ASSERT_EQ(c->propagation.size(), 4u);
  ASSERT_EQ(c->injection.size(), 2u);
  for (const auto& p : c->propagation) EXPECT_GE(p.ms, 0.0);
  for (const auto& i : c->injection) EXPECT_GE(i.delta_ms, i.rho_ms);  // two passes against one
  const std::string md = perf::lpv_costs_markdown(*c);
  EXPECT_NE(md.find("| 16^3 | 16 |"), std::string::npos) << md;
  EXPECT_NE(md.find("0.712"), std::string::npos) << md;  // the paper's 16^3 x 16
  EXPECT_NE(md.find("| 256^2 |"), std::string::npos) << md;
}

TEST(LpvCosts, SizesThatDoNotDivideAreRefused) {
  perf::LpvCostSettings s;
  s.volume_sizes = {8, 12};
  auto c = perf::measure_lpv_costs(s);
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.error().kind, ErrorKind::BadUsage);
  EXPECT_NE(c.error().message.find("volume size 8 must be >= 2 and divide 12"), std::string::npos) << c.error().message;
}

}  // namespace
