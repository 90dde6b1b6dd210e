// Helpers shared by the platform tests: temp folders and a watchdog so that a hang fails the test
// binary loudly instead of blocking CI.
#pragma once
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <functional>
#include <future>
#include <string>
#include <thread>

namespace mrgi::test {

}  // namespace mrgi::test
#include "common/shared_data.h"
namespace mrgi::test {

// A fresh folder under the system temp dir, removed when the object dies.
struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& tag) {
    path = std::filesystem::temp_directory_path() /
           ("mrgi-" + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter()++));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
  static std::atomic<int>& counter() {
    static std::atomic<int> c{0};
    return c;
  }
};

// A shell command's exit status (-1 when it did not exit normally).
inline int run_command(const std::string& cmd) {
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

// A text file's contents (empty when it cannot be read).
inline std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

// Runs fn on another thread; if it has not returned after `limit`, the process aborts with a
// message (a hang is a failure, and a hung thread cannot be cancelled).
inline void run_with_deadline(std::chrono::seconds limit, const std::string& what, std::function<void()> fn) {
  auto done = std::make_shared<std::promise<void>>();
  auto fut = done->get_future();
  std::thread([fn = std::move(fn), done] {
    fn();
    done->set_value();
  }).detach();
  if (fut.wait_for(limit) != std::future_status::ready) {
    std::fprintf(stderr, "FATAL: %s did not finish within %lld s (hang)\n", what.c_str(), (long long)limit.count());
    std::fflush(stderr);
    std::abort();
  }
}

}  // namespace mrgi::test
