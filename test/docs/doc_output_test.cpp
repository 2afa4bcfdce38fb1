// The pages' output blocks are checked against what their commands print: every block marked
// <!-- output: NAME --> is checked by tools/first_hour.sh, and the checker (tools/doc_output.py)
// fails when a block and the output differ.
#include "test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <unistd.h>

namespace
{
namespace fs = std::filesystem;
using cartpole_qlearning::test::CommandRun;
using cartpole_qlearning::test::fileText;
using cartpole_qlearning::test::runCommand;

const fs::path kSource = CARTPOLE_SOURCE_DIR;

class DocOutputTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    dir_ = fs::temp_directory_path() / ("doc_output_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override
  {
    fs::remove_all(dir_);
  }
  std::string write(const std::string& name, const std::string& text) const
  {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  CommandRun check(const std::string& page, const std::string& name, const std::string& log) const
  {
    return runCommand("/usr/bin/python3 " + (kSource / "tools" / "doc_output.py").string() + " " + page + " " + name +
                      " " + log);
  }
  fs::path dir_;
};

// A run's output as roslaunch prints it: colours, a prefix on each line, lines the page leaves out.
const char* const kLog =
    "\x1b[0m[ INFO] [1796227543.07]: episode    250  mean_return_100  450.49  epsilon 0.030  "
    "alpha 0.050  steps/s 146005  time 0.40 s\x1b[0m\n"
    "[ INFO] [1796227543.21]: qlearning_controller: SOLVED after 259 episodes, 61681 steps, 0.4 s "
    "(mean return of the last 100: 477.66); saved to /home/user/.ros/cartpole_qlearning/q.yaml\n"
    "[ INFO] [1796227543.22]: qlearning_controller: done; ending the launch\n";

const char* const kPage =
    "Some prose.\n\n<!-- output: end -->\n```\n$ roslaunch cartpole_qlearning train.launch\n...\n"
    "episode    250  mean_return_100  450.49  epsilon 0.030  alpha 0.050  ...\n"
    "qlearning_controller: SOLVED after 259 episodes, 61681 steps, ... (mean return of the last "
    "100: 477.66); saved to ~/.ros/cartpole_qlearning/q.yaml\n"
    "qlearning_controller: done; ending the launch\n```\n";

TEST_F(DocOutputTest, ABlockThatIsWhatTheCommandPrintedPasses)
{
  const CommandRun run = check(write("page.md", kPage), "end", write("run.log", kLog));
  EXPECT_EQ(0, run.status) << run.output;
}

TEST_F(DocOutputTest, ABlockThatDiffersFromTheOutputFailsNamingTheLine)
{
  const std::string log = write("run.log", kLog);
  // One figure changed in the page: 260 episodes where the run said 259.
  std::string changed = kPage;
  changed.replace(changed.find("after 259"), 9, "after 260");
  const CommandRun run = check(write("page.md", changed), "end", log);
  EXPECT_EQ(1, run.status) << run.output;
  EXPECT_NE(std::string::npos, run.output.find("not in the output after '[ INFO] [1796227543.07]: episode    250"))
      << run.output;
  EXPECT_NE(std::string::npos, run.output.find("SOLVED after 260 episodes")) << run.output;
  // Lines out of order fail too: the block's order is the output's.
  std::string swapped = kPage;
  const std::string last = "qlearning_controller: done; ending the launch\n";
  swapped.erase(swapped.find(last), last.size());
  swapped.insert(swapped.find("episode    250"), last);
  EXPECT_EQ(1, check(write("swapped.md", swapped), "end", log).status);
  // A page with no such block: 2.
  EXPECT_EQ(2, check(write("other.md", "no blocks\n"), "end", log).status);
}

TEST_F(DocOutputTest, AFormBlockChecksTheFormOfRealTimeFigures)
{
  std::string page = kPage;
  page.replace(page.find("<!-- output: end -->"), 20, "<!-- output: end, form -->");
  // Other figures, the same form: passes.
  std::string other = kLog;
  other.replace(other.find("after 259"), 9, "after 300");
  other.replace(other.find("477.66"), 6, "480.12");
  EXPECT_EQ(0, check(write("page.md", page), "end", write("run.log", other)).status);
  // Another word: fails.
  std::string worded = other;
  worded.replace(worded.find("SOLVED"), 6, "FAILED");
  EXPECT_EQ(1, check(write("page.md", page), "end", write("worded.log", worded)).status);
}

// Every block a page marks as a command's output is checked by first_hour.sh, under its page.
TEST(DocOutputBlocks, EveryMarkedBlockIsCheckedByFirstHour)
{
  const std::string first_hour = fileText((kSource / "tools" / "first_hour.sh").string());
  std::set<std::string> pages{"README.md"};
  for (const auto& entry : fs::directory_iterator(kSource / "docs"))
    if (entry.path().extension() == ".md")
      pages.insert("docs/" + entry.path().filename().string());
  std::size_t marked = 0;
  for (const std::string& page : pages)
  {
    const std::string text = fileText((kSource / page).string());
    for (std::size_t at = text.find("<!-- output: "); at != std::string::npos; at = text.find("<!-- output: ", at + 1))
    {
      const std::size_t from = at + 13;
      const std::string name = text.substr(from, text.find_first_of(", ", from) - from);
      ++marked;
      EXPECT_NE(std::string::npos, first_hour.find("output " + page + " " + name + "\n"))
          << page << "'s output block " << name << " is not checked by tools/first_hour.sh";
    }
  }
  EXPECT_GE(marked, 4u);
}

}  // namespace
