// The public ladder of every technique (mrgi/runtime.h technique_ladder): the same levels as
// technique_levels, each knob with a unit, internal scales in (0, 1]; an unknown technique is
// refused by name, and "specular" (docs/DESIGN.md's add-on) with where that stage is.
#include <gtest/gtest.h>

#include "mrgi/runtime.h"

TEST(TechniqueLadder, EveryTechniqueListsItsLevelsWithUnits) {
  for (const std::string& name : mrgi::technique_names()) {
    auto ladder = mrgi::technique_ladder(name);
    ASSERT_TRUE(ladder.ok()) << name;
    auto levels = mrgi::technique_levels(name);
    ASSERT_TRUE(levels.ok()) << name;
    ASSERT_EQ(ladder->size(), levels->size()) << name;
    for (size_t i = 0; i < ladder->size(); ++i) {
      const mrgi::QualityLevelInfo& l = (*ladder)[i];
      EXPECT_EQ(l.name, (*levels)[i]) << name;
      EXPECT_GT(l.internal_scale, 0.0f) << name << " " << l.name;
      EXPECT_LE(l.internal_scale, 1.0f) << name << " " << l.name;
      EXPECT_FALSE(l.knobs.empty()) << name << " " << l.name;
      for (const mrgi::QualityKnob& k : l.knobs) {
        EXPECT_FALSE(k.name.empty()) << name << " " << l.name;
        EXPECT_FALSE(k.unit.empty()) << name << " " << l.name << " " << k.name;
        // The span a knob may be set in is the ladder's own: every level's value lies in it.
        EXPECT_LE(k.min, k.value) << name << " " << l.name << " " << k.name;
        EXPECT_GE(k.max, k.value) << name << " " << l.name << " " << k.name;
      }
    }
  }
  auto none = mrgi::technique_ladder("no-such-technique");
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().message.find("no-such-technique"), std::string::npos) << none.error().message;
  auto specular = mrgi::technique_ladder("specular");
  ASSERT_FALSE(specular.ok());
  EXPECT_EQ(specular.error().kind, mrgi::ErrorKind::BadUsage);
  EXPECT_NE(specular.error().message.find("a stage of every technique"), std::string::npos) << specular.error().message;
  EXPECT_NE(specular.error().message.find("--specular-ablation off"), std::string::npos) << specular.error().message;
}
