// Every image a committed Markdown file shows (![...](path)) exists: reports copied out of a
// bench folder used to point at a pareto.png left behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

TEST(DocLinks, EveryImageAMarkdownFileShowsExists) {
  const fs::path root = MRGI_SOURCE_DIR;
  const std::regex image(R"(!\[[^\]]*\]\(([^)\s]+)\))");
  std::vector<std::string> broken;
  size_t files = 0, links = 0;
  for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator(); ++it) {
    const std::string name = it->path().filename().string();
    if (it->is_directory() && (name == ".git" || name.rfind("build", 0) == 0 || name == "out")) {
      it.disable_recursion_pending();
      continue;
    }
    if (!it->is_regular_file() || it->path().extension() != ".md") continue;
    ++files;
    std::ifstream in(it->path());
    std::stringstream text;
    text << in.rdbuf();
    const std::string s = text.str();
    for (std::sregex_iterator m(s.begin(), s.end(), image), end; m != end; ++m) {
      std::string target = (*m)[1].str();
      if (target.rfind("http", 0) == 0) continue;
      target = target.substr(0, target.find('#'));
      ++links;
      if (!fs::exists(it->path().parent_path() / target))
        broken.push_back(fs::relative(it->path(), root).string() + ": " + target);
    }
  }
  EXPECT_GT(files, 10u);
  EXPECT_GT(links, 5u);
  std::string list;
  for (const std::string& b : broken) list += "\n  " + b;
  EXPECT_TRUE(broken.empty()) << broken.size() << " broken image links:" << list;
}
