// A fresh temporary folder per test, removed afterwards; fixtures are built inside it so the
// repository carries no binary test files.
#pragma once
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <random>
#include <string>

namespace mrgi::testing {

class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("mrgi-" + std::string(info ? info->name() : "test") + "-" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  std::string str() const { return path_.string(); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

inline void write_text(const std::string& path, const std::string& text) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

inline bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

}  // namespace mrgi::testing

// Asserts an Expected failed with KIND and that its message holds every given fragment.
#define EXPECT_ERROR(expr, KIND, ...)                                                   \
  do {                                                                                \
    auto&& mrgi_result_ = (expr);                                                     \
    ASSERT_FALSE(mrgi_result_.ok()) << "expected an error of kind " #KIND;          \
    EXPECT_EQ(mrgi_result_.error().kind, ::mrgi::ErrorKind::KIND)                     \
        << mrgi_result_.error().message;                                              \
    for (const char* mrgi_fragment_ : std::initializer_list<const char*>{__VA_ARGS__})                             \
      EXPECT_TRUE(::mrgi::testing::contains(mrgi_result_.error().message, mrgi_fragment_)) \
          << "message '" << mrgi_result_.error().message << "' lacks '" << mrgi_fragment_ << "'"; \
  } while (0)
