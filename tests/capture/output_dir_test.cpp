// --out safety (mrgi/platform/output_dir.h): only what an mrgi tool created (its marker) or an
// empty folder is ever replaced or deleted; user data, the root, the home and the current folder
// are refused untouched; a failed run removes its own DIR.partial.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "capture/temp_dir.h"
#include "mrgi/platform/output_dir.h"

namespace fs = std::filesystem;
using mrgi::OutputDir;
using mrgi::testing::TempDir;

namespace {

void write(const fs::path& p, const std::string& text = "user data\n") {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

TEST(OutputDir, NewFolderIsBuiltAsPartialAndCommitted) {
  TempDir t;
  const std::string dir = (fs::path(t.str()) / "out").string();
  {
    auto o = OutputDir::begin(dir);
    ASSERT_TRUE(o.ok()) << o.error().message;
    EXPECT_TRUE(fs::is_regular_file(fs::path(o->partial()) / OutputDir::kMarker));
    EXPECT_FALSE(fs::exists(dir));
    write(fs::path(o->partial()) / "result.txt", "1\n");
    ASSERT_TRUE(o->commit().ok());
  }
  EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / "result.txt"));
  EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / OutputDir::kMarker));
  EXPECT_FALSE(fs::exists(dir + ".partial"));
  // A second run replaces its own earlier output.
  auto again = OutputDir::begin(dir);
  ASSERT_TRUE(again.ok()) << again.error().message;
  ASSERT_TRUE(again->commit().ok());
  EXPECT_FALSE(fs::exists(fs::path(dir) / "result.txt"));
}

TEST(OutputDir, UserDataIsNeverReplacedOrDeleted) {
  TempDir t;
  // A folder with the user's files, even one named like an output's.
  const fs::path user = fs::path(t.str()) / "photos";
  write(user / "summary.json");
  write(user / "bench.json");
  auto o = OutputDir::begin(user.string());
  ASSERT_FALSE(o.ok());
  EXPECT_EQ(o.error().kind, mrgi::ErrorKind::BadUsage);
  EXPECT_NE(o.error().message.find("not written by mrgi"), std::string::npos) << o.error().message;
  EXPECT_TRUE(fs::exists(user / "summary.json"));
  // A user folder named DIR.partial is refused too, untouched.
  const fs::path dir = fs::path(t.str()) / "run";
  write(fs::path(dir.string() + ".partial") / "notes.txt");
  auto p = OutputDir::begin(dir.string());
  ASSERT_FALSE(p.ok());
  EXPECT_TRUE(fs::exists(fs::path(dir.string() + ".partial") / "notes.txt"));
  // A file, a symlink.
  write(fs::path(t.str()) / "file.txt");
  EXPECT_FALSE(OutputDir::begin((fs::path(t.str()) / "file.txt").string()).ok());
  fs::create_directory_symlink(user, fs::path(t.str()) / "link");
  EXPECT_FALSE(OutputDir::begin((fs::path(t.str()) / "link").string()).ok());
  EXPECT_TRUE(fs::exists(user / "bench.json"));
  // An empty folder may be used.
  fs::create_directories(fs::path(t.str()) / "empty");
  auto e = OutputDir::begin((fs::path(t.str()) / "empty").string());
  ASSERT_TRUE(e.ok()) << e.error().message;
}

TEST(OutputDir, RootHomeAndCurrentFolderAreRefused) {
  TempDir t;
  EXPECT_FALSE(OutputDir::begin("/").ok());
  EXPECT_FALSE(OutputDir::begin("//").ok());
  EXPECT_FALSE(OutputDir::begin("").ok());
  const fs::path before = fs::current_path();
  fs::create_directories(fs::path(t.str()) / "work" / "sub");
  fs::current_path(fs::path(t.str()) / "work" / "sub");
  auto cur = OutputDir::begin(".");
  auto parent = OutputDir::begin("..");
  fs::current_path(before);
  EXPECT_FALSE(cur.ok());
  EXPECT_FALSE(parent.ok());
  if (const char* home = std::getenv("HOME"); home && *home) {
    EXPECT_FALSE(OutputDir::begin(home).ok());
  }
}

TEST(OutputDir, AFailedRunRemovesOnlyItsOwnPartial) {
  TempDir t;
  const std::string dir = (fs::path(t.str()) / "out").string();
  {
    auto o = OutputDir::begin(dir);
    ASSERT_TRUE(o.ok());
    write(fs::path(o->partial()) / "half.png");
    // Destroyed without commit(): the run failed.
  }
  EXPECT_FALSE(fs::exists(dir + ".partial"));
  EXPECT_FALSE(fs::exists(dir));
}

}  // namespace
