#include "technique/knobs.h"

#include <cstdio>

namespace mrgi::technique {

std::string knob_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace mrgi::technique
