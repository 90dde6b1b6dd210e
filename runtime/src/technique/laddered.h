// What every technique's class holds the same way: its name, its quality ladder (the generic
// levels and knobs, technique.h) and its typed levels with RuntimeSettings::knobs applied, and
// the check that a frame's level is one of them.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "technique/technique.h"

namespace mrgi::technique {

template <class Level>
class Laddered : public Technique {
 public:
  // `levels` by reference: the ladder made from it in the same call is evaluated first.
  Laddered(std::string name, std::vector<QualityLevel> ladder, std::vector<Level>&& levels)
      : name_(std::move(name)), ladder_(std::move(ladder)), levels_(std::move(levels)) {}
  const std::string& name() const final { return name_; }
  const std::vector<QualityLevel>& levels() const final { return ladder_; }

 protected:
  // The typed level a frame asks for; BadUsage naming the technique and its levels otherwise.
  Expected<const Level*> level_for(const frame::FrameInfo& info) const {
    if (info.level < 0 || info.level >= int(levels_.size()))
      return fail(ErrorKind::BadUsage, name_ + ": level " + std::to_string(info.level) + " outside 0.." +
                                           std::to_string(levels_.size() - 1));
    return &levels_[size_t(info.level)];
  }

  const std::string name_;
  const std::vector<QualityLevel> ladder_;
  const std::vector<Level> levels_;  // the defaults with RuntimeSettings::knobs applied
};

}  // namespace mrgi::technique
