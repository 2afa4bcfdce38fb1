// Every relative link in README.md and the pages under docs/ (docs/*.md and the developers' notes in
// its folders) leads somewhere: the file or folder exists and,
// for a link with #anchor into a Markdown page, that page has a heading with that anchor. The
// pages move text between one another; a link left pointing at where the text was fails here.
// Anchors are made the way GitHub makes them, since that is where users read the pages.
#include "test_support.h"
#include "text_match.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace
{
namespace fs = std::filesystem;
using cartpole_qlearning::test::fileText;
namespace text_match = cartpole_qlearning::test::text_match;

const fs::path kSource = CARTPOLE_SOURCE_DIR;

// The lines of a page outside fenced code blocks: a "[x](y)" or "# x" inside a block of
// commands or output is not Markdown.
std::vector<std::string> proseLines(const std::string& text)
{
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  bool fenced = false;
  while (std::getline(in, line))
  {
    const std::size_t first = line.find_first_not_of(' ');
    if (first != std::string::npos && line.compare(first, 3, "```") == 0)
    {
      fenced = !fenced;
      continue;
    }
    lines.push_back(fenced ? std::string() : line);
  }
  return lines;
}

// A heading's anchor as GitHub derives it: the text as rendered (code spans and link targets
// dropped, their text kept), lower case, anything but letters, digits, '-', '_' and spaces
// removed, spaces made '-'. Non-ASCII characters are dropped too: GitHub keeps non-ASCII
// letters, which no heading here has; should one come, its links fail here rather than pass.
std::string anchorOf(std::string heading)
{
  static const std::string link = R"(!?\[([^\]]*)\]\([^)]*\))";
  heading = text_match::replaceAll(heading, link, "$1");
  std::string anchor;
  for (const char c : heading)
  {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x80)
      continue;
    if (std::isalnum(u) || c == '-' || c == '_')
      anchor += static_cast<char>(std::tolower(u));
    else if (c == ' ')
      anchor += '-';
  }
  return anchor;
}

// Every anchor a page's headings give, with GitHub's -1, -2, ... for repeated headings.
std::set<std::string> anchorsOf(const std::string& text)
{
  static const std::string heading = R"(^#{1,6}\s+(.*?)\s*#*\s*$)";
  std::set<std::string> anchors;
  std::map<std::string, int> seen;
  for (const std::string& line : proseLines(text))
  {
    text_match::Groups m;
    if (!text_match::matchesWhole(line, heading, &m))
      continue;
    const std::string anchor = anchorOf(m[1]);
    const int n = seen[anchor]++;
    anchors.insert(n == 0 ? anchor : anchor + "-" + std::to_string(n));
  }
  return anchors;
}

// The link targets of a page: Markdown links and images, reference definitions, and the src and
// href of HTML tags. Code spans are left out first: `[a](b)` there is an example, not a link.
std::vector<std::string> linksOf(const std::string& text)
{
  static const std::string code_span = "`[^`]*`";
  static const std::string inline_link = R"re(\]\(\s*<?([^)\s>]+)>?(?:\s+"[^"]*")?\s*\))re";
  static const std::string reference = R"(^\s*\[[^\]]+\]:\s*(\S+))";
  static const std::string html = R"re(\b(?:src|href)\s*=\s*"([^"]+)")re";
  std::vector<std::string> links;
  for (const std::string& raw : proseLines(text))
  {
    const std::string line = text_match::replaceAll(raw, code_span, "``");
    for (const std::string* pattern : {&inline_link, &html})
      for (const text_match::Groups& link : text_match::allMatches(line, *pattern))
        links.push_back(link[1]);
    text_match::Groups m;
    if (text_match::contains(line, reference, &m))
      links.push_back(m[1]);
  }
  return links;
}

bool isExternal(const std::string& target)
{
  return text_match::contains(target, "^[a-zA-Z][a-zA-Z0-9+.-]*:");
}

// What is wrong with one relative link of `page`, or "" when it leads somewhere.
std::string brokenBecause(const fs::path& page, const std::string& target)
{
  const std::size_t hash = target.find('#');
  const std::string path = target.substr(0, hash);
  const std::string anchor = hash == std::string::npos ? "" : target.substr(hash + 1);
  const fs::path file = path.empty() ? page : page.parent_path() / path;
  if (!fs::exists(file))
    return "no such file: " + fs::relative(file.lexically_normal(), kSource).string();
  if (anchor.empty() || file.extension() != ".md")
    return "";
  if (anchorsOf(fileText(file)).count(anchor) == 0)
    return "no heading in " + fs::relative(file.lexically_normal(), kSource).string() + " gives #" + anchor;
  return "";
}

// README.md, then every Markdown page under docs/, in its folders too (docs/notes/).
std::vector<fs::path> pages()
{
  std::vector<fs::path> found{kSource / "README.md"};
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(kSource / "docs"))
    if (entry.is_regular_file() && entry.path().extension() == ".md")
      found.push_back(entry.path());
  std::sort(found.begin() + 1, found.end());
  return found;
}

// Whether a relative link of `page` leads to README.md (from docs/ that is ../README.md, from
// docs/notes/ ../../README.md), with or without an anchor.
bool leadsToTheReadme(const fs::path& page, const std::string& target)
{
  if (isExternal(target))
    return false;
  const fs::path file = (page.parent_path() / target.substr(0, target.find('#'))).lexically_normal();
  return file == (kSource / "README.md").lexically_normal();
}

TEST(DocsLinksTest, AnchorsAreGitHubs)
{
  EXPECT_EQ(anchorOf("Tile coding: `learning/features: tiles`"), "tile-coding-learningfeatures-tiles");
  EXPECT_EQ(anchorOf("The Q-learning tutorial's worked example"), "the-q-learning-tutorials-worked-example");
  EXPECT_EQ(anchorOf("Robust tables: `config/robust.yaml`"), "robust-tables-configrobustyaml");
  EXPECT_EQ(anchorOf("See [Nodes](nodes.md) and snake_case"), "see-nodes-and-snake_case");
  const std::set<std::string> twice = anchorsOf("# Usage\n```\n# not a heading\n```\n## Usage\n### Usage ##\n");
  EXPECT_EQ(twice, (std::set<std::string>{"usage", "usage-1", "usage-2"}));
}

TEST(DocsLinksTest, LinksAreFoundWhereMarkdownHasThem)
{
  const std::vector<std::string> links = linksOf(
      "[a](a.md) and ![b](images/b.png \"title\") and `[c](c.md)`\n"
      "```\n[d](d.md)\n```\n[e]: e.md\n<img src=\"f.png\" width=\"49%\"> [g](https://example.org)\n");
  EXPECT_EQ(links, (std::vector<std::string>{"a.md", "images/b.png", "e.md", "https://example.org", "f.png"}));
}

TEST(DocsLinksTest, ABrokenLinkIsCaught)
{
  const fs::path readme = kSource / "README.md";
  EXPECT_EQ(brokenBecause(readme, "docs/no_such_page.md"), "no such file: docs/no_such_page.md");
  EXPECT_EQ(brokenBecause(readme, "#no-such-heading"), "no heading in README.md gives #no-such-heading");
  EXPECT_EQ(brokenBecause(readme, "#documentation"), "");
}

TEST(DocsLinksTest, TheDevelopersNotesAreAmongThePagesChecked)
{
  const std::vector<fs::path> found = pages();
  EXPECT_NE(std::find(found.begin(), found.end(), kSource / "docs" / "notes" / "tuning.md"), found.end())
      << "docs/notes/tuning.md is not among the pages whose links are checked";
  const fs::path notes = kSource / "docs" / "notes" / "tuning.md";
  EXPECT_TRUE(leadsToTheReadme(notes, "../../README.md#documentation"));
  EXPECT_FALSE(leadsToTheReadme(notes, "../README.md#documentation"));
  EXPECT_TRUE(leadsToTheReadme(kSource / "docs" / "design.md", "../README.md"));
  EXPECT_FALSE(leadsToTheReadme(kSource / "docs" / "design.md", "https://example.org/README.md"));
}

TEST(DocsLinksTest, EveryRelativeLinkInTheReadmeAndDocsLeadsSomewhere)
{
  std::size_t checked = 0;
  for (const fs::path& page : pages())
  {
    for (const std::string& target : linksOf(fileText(page)))
    {
      if (isExternal(target))
        continue;
      ++checked;
      const std::string why = brokenBecause(page, target);
      EXPECT_EQ(why, "") << fs::relative(page, kSource).string() << " links to " << target;
    }
  }
  // The README's index alone links to every page: far fewer means the links were not read.
  EXPECT_GT(checked, 30u) << "links found in README.md and docs/*.md";
}

TEST(DocsLinksTest, EveryDocsPageLinksBackToTheReadme)
{
  for (const fs::path& page : pages())
  {
    if (page.filename() == "README.md")
      continue;
    const std::vector<std::string> links = linksOf(fileText(page));
    const bool back =
        std::any_of(links.begin(), links.end(), [&page](const std::string& l) { return leadsToTheReadme(page, l); });
    EXPECT_TRUE(back) << fs::relative(page, kSource).string() << " has no link back to the README";
  }
}

// The users' pages are read to find how to do a thing: each stays short enough to read (300 lines),
// and none sends the reader to the project's issue tracker for its meaning ("issue 26's robot").
// The developers' notes (docs/notes/) keep the record of tuning rounds and may run long.
TEST(DocsLinksTest, EveryUsersPageIsShortAndNamesNoIssue)
{
  const std::regex issue("\\bissues? #?[0-9]+", std::regex::icase);
  std::size_t checked = 0;
  for (const fs::path& page : pages())
  {
    if (page.parent_path().filename() == "notes")
      continue;
    ++checked;
    const std::string text = fileText(page);
    const std::string name = fs::relative(page, kSource).string();
    EXPECT_LE(std::count(text.begin(), text.end(), '\n'), 300) << name << " is over 300 lines";
    std::smatch found;
    EXPECT_FALSE(std::regex_search(text, found, issue)) << name << " names an issue: " << found.str();
  }
  EXPECT_GT(checked, 10u) << "pages found in README.md and docs/";
  EXPECT_TRUE(std::regex_search(std::string("as issue 26 found"), issue));
  EXPECT_FALSE(std::regex_search(std::string("a tissue 26 mm thick"), issue));
}

}  // namespace
