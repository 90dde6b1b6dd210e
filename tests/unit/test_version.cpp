// mrgi/version.h: the linked library's version is the one the headers were configured with, and
// reads MAJOR.MINOR.PATCH.
#include <gtest/gtest.h>

#include <string>

#include "mrgi/version.h"

namespace {

TEST(Version, TheLibraryReportsTheVersionItsHeadersCarry) {
  EXPECT_STREQ(mrgi::version(), MRGI_VERSION_STRING);
  const mrgi::Version v = mrgi::version_numbers();
  EXPECT_EQ(v.major, MRGI_VERSION_MAJOR);
  EXPECT_EQ(v.minor, MRGI_VERSION_MINOR);
  EXPECT_EQ(v.patch, MRGI_VERSION_PATCH);
  EXPECT_EQ(std::string(mrgi::version()),
            std::to_string(v.major) + "." + std::to_string(v.minor) + "." + std::to_string(v.patch));
}

}  // namespace
