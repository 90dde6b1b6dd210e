// Every relative link and image in the repository's Markdown files resolves to a file or folder
// that exists (images included: a report copied out of a bench folder once pointed at a pareto.png
// left behind): a reader following the README, the docs or a result's report never lands on a
// path that was moved or never committed. Web links (scheme://, mailto:) and in-page anchors
// are not checked; a link's own anchor (#section) is dropped before the path is looked up.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

// Markdown files of the repository, without build outputs and version control.
std::vector<fs::path> markdown_files(const fs::path& root) {
  std::vector<fs::path> files;
  const auto skip = [&](const fs::path& p) {
    const std::string top = fs::relative(p, root).begin()->string();
    return top == ".git" || top == "out" || top.rfind("build", 0) == 0;
  };
  for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator(); ++it) {
    if (it->is_directory() && skip(it->path())) {
      it.disable_recursion_pending();
      continue;
    }
    if (it->is_regular_file() && it->path().extension() == ".md") files.push_back(it->path());
  }
  return files;
}

// The targets of [text](target) and ![alt](target) outside code spans and fenced blocks.
std::vector<std::string> link_targets(const std::string& text) {
  std::vector<std::string> targets;
  static const std::regex link(R"(\]\(([^)\s]+)(\s+"[^"]*")?\))");
  static const std::regex code_span("`[^`]*`");
  std::istringstream in(text);
  std::string line;
  bool fenced = false;
  while (std::getline(in, line)) {
    if (line.rfind("```", 0) == 0 || line.rfind("    ```", 0) == 0) {
      fenced = !fenced;
      continue;
    }
    if (fenced) continue;
    const std::string plain = std::regex_replace(line, code_span, "");
    for (auto m = std::sregex_iterator(plain.begin(), plain.end(), link); m != std::sregex_iterator(); ++m)
      targets.push_back((*m)[1].str());
  }
  return targets;
}

TEST(MarkdownLinks, EveryRelativeLinkResolves) {
  const fs::path root = MRGI_SOURCE_DIR;
  const auto files = markdown_files(root);
  ASSERT_FALSE(files.empty()) << "no Markdown files under " << root;
  size_t checked = 0;
  for (const fs::path& file : files) {
    std::ifstream in(file);
    const std::string text((std::istreambuf_iterator<char>(in)), {});
    for (std::string target : link_targets(text)) {
      if (target.find("://") != std::string::npos || target.rfind("mailto:", 0) == 0 || target[0] == '#') continue;
      if (const size_t hash = target.find('#'); hash != std::string::npos) target.resize(hash);
      if (target.size() > 1 && target.front() == '<' && target.back() == '>') target = target.substr(1, target.size() - 2);
      const fs::path resolved = target[0] == '/' ? root / target.substr(1) : file.parent_path() / target;
      ++checked;
      EXPECT_TRUE(fs::exists(resolved)) << fs::relative(file, root).string() << ": link '" << target
                                        << "' resolves to nothing (" << resolved.lexically_normal().string() << ")";
    }
  }
  EXPECT_GT(checked, 20u) << "the README and the results link to each other: too few links found";
  std::printf("%zu relative links checked in %zu Markdown files\n", checked, files.size());
}

TEST(MarkdownLinks, TheParserFindsLinksAndSkipsCode) {
  const auto t = link_targets("see [a](docs/a.md) and ![pic](img.png \"title\")\n`[not](code.md)`\n```\n[x](fenced.md)\n```\n"
                              "[web](https://example.com) [anchor](#part)\n");
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t[0], "docs/a.md");
  EXPECT_EQ(t[1], "img.png");
  EXPECT_EQ(t[2], "https://example.com");
  EXPECT_EQ(t[3], "#part");
}

}  // namespace
