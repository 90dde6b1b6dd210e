// Test data from ../shared/data (real recordings, photos, models nobody here made). It is not part
// of the repository, so a test that needs it skips with a message naming the missing file instead
// of failing or crashing on a clone without it. MRGI_SHARED_DIR (environment) overrides the
// compiled-in location, which is how the skip path itself is checked:
//   MRGI_SHARED_DIR=/nonexistent ctest
#pragma once
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace mrgi::test {

inline std::string shared_root() {
  const char* env = std::getenv("MRGI_SHARED_DIR");
  return env && *env ? std::string(env) : std::string(MRGI_SHARED_DIR);
}

// The path of REL under ../shared/data (it may not exist).
inline std::string shared_data(const std::string& rel) { return shared_root() + "/data/" + rel; }

}  // namespace mrgi::test

// Skips the current test, with a message, when PATH (from shared_data) is absent.
#define MRGI_SKIP_WITHOUT_SHARED(path)                                                      \
  do {                                                                                      \
    std::error_code mrgi_ec_;                                                               \
    if (!std::filesystem::exists((path), mrgi_ec_))                                         \
      GTEST_SKIP() << "needs ../shared test data: " << (path) << " is absent";              \
  } while (0)
