// train_headless's command line parsed without a process: every option into its field, every
// value refused with its reason, every rule of which options go together, and the run settings
// the options make.
#include "headless_options.h"

#include <gtest/gtest.h>

#include <sstream>

using namespace cartpole_qlearning;

namespace
{
std::vector<std::string> words(const std::string& line)
{
  std::istringstream in(line);
  std::vector<std::string> args;
  for (std::string word; in >> word;)
    args.push_back(word);
  return args;
}

HeadlessCommandLine parse(const std::string& line)
{
  return parseHeadlessOptions(words(line));
}

// The refusal of a command line that must be refused.
std::string refusal(const std::string& line)
{
  const HeadlessCommandLine parsed = parse(line);
  EXPECT_FALSE(parsed.error.empty()) << line;
  return parsed.error;
}

TEST(HeadlessOptions, NoArgumentsTrainWithTheDefaults)
{
  const HeadlessCommandLine parsed = parse("");
  ASSERT_EQ("", parsed.error);
  const HeadlessOptions& o = parsed.options;
  EXPECT_FALSE(o.help);
  EXPECT_FALSE(o.seed.has_value());
  EXPECT_EQ(1u, o.robots);
  EXPECT_EQ("/cartpole", o.name_space);
  EXPECT_EQ(0u, o.max_episodes);
  EXPECT_EQ(RunSettings().checkpoint_every, o.checkpoint_every);
  EXPECT_EQ(100u, o.evaluation_episodes);
  EXPECT_EQ(PolicyGridParams().points, o.grid_points);
  EXPECT_EQ("theta,theta_dot", o.axes);
  EXPECT_EQ("none", o.previous);
  EXPECT_FALSE(o.evaluating());
  EXPECT_TRUE(o.typed.empty());
}

TEST(HeadlessOptions, EveryOptionGoesIntoItsField)
{
  const HeadlessCommandLine parsed = parse(
      "--config c.yaml --seed 7 --robots 3 --ns a/b --max-episodes 40 --save s.yaml --load l.yaml "
      "--checkpoint-every 0 --stats-csv c.csv --quiet --returns --trace");
  ASSERT_EQ("", parsed.error);
  const HeadlessOptions& o = parsed.options;
  EXPECT_EQ("c.yaml", o.config_path);
  EXPECT_EQ(7u, o.seed.value());
  EXPECT_EQ(3u, o.robots);
  EXPECT_EQ("/a/b", o.name_space);  // made absolute
  EXPECT_EQ(40u, o.max_episodes);
  EXPECT_EQ("s.yaml", o.save_path);
  EXPECT_EQ("l.yaml", o.load_path);
  EXPECT_EQ(0u, o.checkpoint_every);
  EXPECT_TRUE(o.checkpoint_given);
  EXPECT_EQ("c.csv", o.stats_csv_path);
  EXPECT_TRUE(o.quiet);
  EXPECT_TRUE(o.print_returns);
  EXPECT_TRUE(o.trace);
  EXPECT_EQ(std::vector<std::string>({"--config", "--seed", "--robots", "--ns", "--max-episodes", "--save", "--load",
                                      "--checkpoint-every", "--stats-csv", "--quiet", "--returns", "--trace"}),
            o.typed);

  const HeadlessOptions e = parse("--evaluate t.yaml --episodes 20 --suite s.yaml").options;
  EXPECT_TRUE(e.evaluating());
  EXPECT_EQ("t.yaml", e.evaluate_path);
  EXPECT_EQ(20u, e.evaluation_episodes);
  EXPECT_TRUE(e.episodes_given);
  EXPECT_EQ("s.yaml", e.suite_path);
  EXPECT_EQ(kEvaluationMaxSteps, e.max_steps);
  EXPECT_EQ(3000u, parse("--evaluate t.yaml --max-steps 3000").options.max_steps);
  EXPECT_EQ(0u, e.predict_delay);
  EXPECT_EQ(1u, parse("--evaluate t.yaml --suite s.yaml --predict-delay 1").options.predict_delay);
  EXPECT_EQ(1u, headlessRunSettings(parse("--evaluate t.yaml --predict-delay 1").options, 0, "/tables", "c.yaml", "")
                    .predict_delay_steps);

  const HeadlessOptions p = parse("--policy t.yaml --grid 11 --axes x,theta --at x_dot=1 --previous 0").options;
  EXPECT_EQ("t.yaml", p.policy_path);
  EXPECT_EQ(11u, p.grid_points);
  EXPECT_EQ("x,theta", p.axes);
  EXPECT_EQ("x_dot=1", p.policy_at);
  EXPECT_EQ("0", p.previous);

  EXPECT_EQ("r.yaml", parse("--replay r.yaml").options.replay_path);
  EXPECT_EQ("/abs", parse("--ns /abs").options.name_space);
  EXPECT_EQ("runs/x", parse("--resume runs/x --no-run-folder").options.resume_folder);
  EXPECT_TRUE(parse("--no-run-folder").options.no_run_folder);
  EXPECT_EQ(10u, parse("--greedy-check 10").options.greedy_check);
  EXPECT_EQ(0u, parse("").options.greedy_check);
}

TEST(HeadlessOptions, HelpStopsReadingWhateverFollows)
{
  for (const std::string line : {"--help", "-h", "--seed 1 --help --bogus", "--evaluate t.yaml --save s --help"})
  {
    const HeadlessCommandLine parsed = parse(line);
    EXPECT_TRUE(parsed.options.help) << line;
    EXPECT_EQ("", parsed.error) << line;
  }
  // What comes before it is read first.
  EXPECT_EQ("unknown or incomplete argument '--bogus'", refusal("--bogus --help"));
}

TEST(HeadlessOptions, BadValuesAreRefusedNamingTheOptionTheValueAndWhatIsAllowed)
{
  EXPECT_EQ("--seed minus-one is not allowed (must be a whole number >= 0)", refusal("--seed minus-one"));
  EXPECT_EQ("--seed -1 is not allowed (must be a whole number >= 0)", refusal("--seed -1"));
  EXPECT_EQ("--seed 99999999999999999999 is not allowed (must be a whole number >= 0)",
            refusal("--seed 99999999999999999999"));
  EXPECT_EQ("--robots 0 is not allowed (must be a whole number in [1, 1000])", refusal("--robots 0"));
  EXPECT_EQ("--robots 1001 is not allowed (must be a whole number in [1, 1000])", refusal("--robots 1001"));
  EXPECT_EQ("--max-episodes 0 is not allowed (must be a whole number >= 1)", refusal("--max-episodes 0"));
  EXPECT_EQ("--checkpoint-every often is not allowed (must be a whole number >= 0; 0: no checkpoints)",
            refusal("--checkpoint-every often"));
  EXPECT_EQ("--episodes 0 is not allowed (must be a whole number >= 1)", refusal("--evaluate t.yaml --episodes 0"));
  EXPECT_EQ("--max-steps 0 is not allowed (must be a whole number in [1, 2147483647])",
            refusal("--evaluate t.yaml --max-steps 0"));
  EXPECT_EQ("--grid 1 is not allowed (must be a whole number in [2, 1000])", refusal("--policy t.yaml --grid 1"));
  EXPECT_EQ("--grid 1001 is not allowed (must be a whole number in [2, 1000])", refusal("--policy t.yaml --grid 1001"));
  EXPECT_EQ("--ns 'a/../b' is not allowed (must be a ROS namespace)", refusal("--ns a/../b"));
  EXPECT_EQ("--ns '' is not allowed (must be a ROS namespace)", parseHeadlessOptions({"--ns", ""}).error);
  EXPECT_EQ("--greedy-check 0 is not allowed (must be a whole number in [1, 1000])", refusal("--greedy-check 0"));
  EXPECT_EQ("--greedy-check ten is not allowed (must be a whole number in [1, 1000])", refusal("--greedy-check ten"));
  // The first bad value is the one refused.
  EXPECT_EQ("--robots 0 is not allowed (must be a whole number in [1, 1000])", refusal("--robots 0 --seed x"));
}

TEST(HeadlessOptions, UnknownOrIncompleteOptionsAreRefusedWithTheUsage)
{
  for (const std::string option : {"--bogus", "--save", "--seed", "--evaluate", "--policy", "--grid", "-x", "t.yaml"})
  {
    const HeadlessCommandLine parsed = parse("--quiet " + option);
    EXPECT_EQ("unknown or incomplete argument '" + option + "'", parsed.error);
    EXPECT_TRUE(parsed.usage_after_error) << option;
  }
  EXPECT_FALSE(parse("--seed x").usage_after_error);
  EXPECT_FALSE(parse("--episodes 5").usage_after_error);
}

TEST(HeadlessOptions, EachRuleRefusesWhatDoesNotGoTogether)
{
  const std::string policy = ": draw a table's policy: give them with --policy TABLE";
  EXPECT_EQ("--grid, --axes, --at and --previous" + policy, refusal("--grid 11"));
  EXPECT_EQ("--grid, --axes, --at and --previous" + policy, refusal("--previous 1 --seed 3"));
  const std::string alone = " with --policy: a policy is drawn from the table alone (its file says its features)";
  EXPECT_EQ("--seed" + alone, refusal("--policy t.yaml --seed 3"));
  EXPECT_EQ("--robots" + alone, refusal("--policy t.yaml --grid 5 --robots 1"));  // as typed, even the default
  EXPECT_EQ("--quiet" + alone, refusal("--quiet --policy t.yaml --seed 3"));      // the first typed
  EXPECT_EQ("", parse("--policy t.yaml --ns a --grid 5 --axes x,theta --at x_dot=1 --previous 1").error);
  EXPECT_EQ("--load and --resume: give one: --resume goes on from a run's own checkpoint",
            refusal("--load a.yaml --resume runs/b"));
  EXPECT_EQ("--episodes: counts --evaluate's episodes (training: --max-episodes)", refusal("--episodes 5"));
  EXPECT_EQ("--max-steps: is how long --evaluate's episodes are (training's: the config's task/max_episode_steps)",
            refusal("--max-steps 3000"));
  EXPECT_EQ(
      "--predict-delay: is how a greedy table meets a robot that answers late: give it with --evaluate TABLE "
      "(training learns from the states it observes)",
      refusal("--predict-delay 1"));
  EXPECT_EQ("--predict-delay 51 is not allowed (must be auto or a whole number in [0, 50])",
            refusal("--evaluate t.yaml --predict-delay 51"));
  const std::string evaluation = " with --evaluate: an evaluation learns nothing and writes nothing";
  for (const std::string option : {"--load l", "--resume r", "--save s", "--max-episodes 3", "--checkpoint-every 0",
                                   "--no-run-folder", "--stats-csv c", "--trace", "--replay r", "--greedy-check 10"})
    EXPECT_EQ(words(option)[0] + evaluation, refusal("--evaluate t.yaml " + option));
  const std::string replay = " with --replay: a replay learns from its file alone";
  for (const std::string option : {"--robots 2", "--max-episodes 3", "--stats-csv c", "--load l",
                                   "--checkpoint-every 0", "--no-run-folder", "--greedy-check 10"})
    EXPECT_EQ(words(option)[0] + replay, refusal("--replay r.yaml " + option));
  EXPECT_EQ("--resume with --replay: a replay learns from its file alone", refusal("--replay r.yaml --resume x"));
  EXPECT_EQ("", parse("--replay r.yaml --robots 1 --seed 2 --save s.yaml --config c.yaml --quiet").error);
  EXPECT_EQ("--suite: runs a table: give it with --evaluate TABLE", refusal("--suite s.yaml"));
  const std::string suite =
      " with --suite: the suite file gives each case's episodes and their length, run on one "
      "robot";
  for (const std::string option : {"--episodes 3", "--max-steps 9", "--robots 2", "--returns"})
    EXPECT_EQ(words(option)[0] + suite, refusal("--evaluate t.yaml --suite s.yaml " + option));
  EXPECT_EQ("", parse("--evaluate t.yaml --suite s.yaml --robots 1 --seed 3 --quiet").error);
  EXPECT_EQ("--checkpoint-every with --no-run-folder: checkpoints go into the run's folder",
            refusal("--no-run-folder --checkpoint-every 5"));
  EXPECT_EQ("", parse("--no-run-folder --checkpoint-every 0").error);  // no checkpoints: nothing to put there
  const std::string average = " with --average: --average writes the mean of tables, nothing else";
  for (const std::string option : {"--config c.yaml", "--seed 1", "--evaluate t.yaml", "--no-run-folder",
                                   "--load l.yaml", "--robots 1", "--suite s.yaml"})
    EXPECT_EQ(words(option)[0] + average, refusal("--average a.yaml --average b.yaml --save m.yaml " + option));
  EXPECT_EQ("--average: give --save PATH, where the mean of the tables goes",
            refusal("--average a.yaml --average b.yaml"));
  EXPECT_EQ("--average a.yaml: give two tables or more, --average before each",
            refusal("--average a.yaml --save m.yaml"));
  const HeadlessCommandLine averaged =
      parse("--average a.yaml --ns n --average /t/b.yaml --quiet --average c.yaml --save m.yaml");
  EXPECT_EQ("", averaged.error);
  EXPECT_EQ((std::vector<std::string>{"a.yaml", "/t/b.yaml", "c.yaml"}), averaged.options.average_paths);
}

TEST(HeadlessOptions, TheRulesAreCheckedInTheTablesOrder)
{
  // --episodes without --evaluate comes before what --replay excludes.
  EXPECT_EQ("--episodes: counts --evaluate's episodes (training: --max-episodes)",
            refusal("--replay r.yaml --robots 2 --episodes 3"));
  // Within a rule, its list's order: --load before --save.
  EXPECT_EQ("--load with --evaluate: an evaluation learns nothing and writes nothing",
            refusal("--evaluate t.yaml --save s --load l"));
  EXPECT_EQ(13u, headlessOptionRules().size());
  for (const OptionRule& rule : headlessOptionRules())
  {
    EXPECT_FALSE(rule.others.empty()) << rule.option.name;
    EXPECT_FALSE(rule.why.empty()) << rule.option.name;
  }
}

TEST(HeadlessOptions, AnEmptyPathIsNoOption)
{
  // As before: --evaluate "" trains, --policy "" draws nothing.
  const HeadlessCommandLine evaluate = parseHeadlessOptions({"--evaluate", "", "--save", "s.yaml"});
  EXPECT_EQ("", evaluate.error);
  EXPECT_FALSE(evaluate.options.evaluating());
  EXPECT_EQ("--grid, --axes, --at and --previous: draw a table's policy: give them with --policy TABLE",
            parseHeadlessOptions({"--policy", "", "--grid", "5"}).error);
}

TEST(HeadlessOptions, TheRunSettingsAreTheControllersParametersFromTheCommandLine)
{
  const HeadlessOptions training = parse("--seed 3 --save s.yaml --load l.yaml --checkpoint-every 7 --trace").options;
  const RunSettings t = headlessRunSettings(training, 3, "/tables", "/etc/c/config.yaml", "/pkg");
  EXPECT_TRUE(t.learning());
  EXPECT_EQ(3u, t.seed);
  EXPECT_EQ("/cartpole", t.name_space);
  EXPECT_EQ("/tables", t.q_table_dir);
  EXPECT_EQ("s.yaml", t.q_table_path);
  EXPECT_EQ("l.yaml", t.load_on_start);
  EXPECT_EQ("", t.stats_csv);  // the run folder's episodes.csv
  EXPECT_EQ(7u, t.checkpoint_every);
  EXPECT_TRUE(t.save_on_shutdown);
  EXPECT_TRUE(t.run_folder);
  EXPECT_TRUE(t.trace);
  EXPECT_TRUE(t.own_absolute_paths);
  EXPECT_EQ(std::vector<std::string>({"/etc/c", "/pkg/config"}), t.suite_folders);

  const RunSettings bare = headlessRunSettings(parse("--no-run-folder").options, 0, "/tables", "c.yaml", "");
  EXPECT_EQ("", bare.q_table_path);  // no default table either
  EXPECT_EQ("none", bare.stats_csv);
  EXPECT_EQ(0u, bare.checkpoint_every);
  EXPECT_FALSE(bare.save_on_shutdown);
  EXPECT_FALSE(bare.run_folder);
  EXPECT_EQ(std::vector<std::string>({"."}), bare.suite_folders);
  // Training's default table is named after its config: no config replaces another's.
  EXPECT_EQ("q_table_c.yaml", headlessRunSettings(parse("").options, 0, "/t", "/etc/c.yaml", "").q_table_path);
  EXPECT_EQ("q_table.yaml",
            headlessRunSettings(parse("").options, 0, "/t", "/pkg/config/cartpole.yaml", "").q_table_path);
  EXPECT_EQ("s.yaml",
            headlessRunSettings(parse("--no-run-folder --save s.yaml").options, 0, "/t", "c.yaml", "").q_table_path);
  EXPECT_EQ("c.csv",
            headlessRunSettings(parse("--no-run-folder --stats-csv c.csv").options, 0, "/t", "c.yaml", "").stats_csv);

  const RunSettings evaluation =
      headlessRunSettings(parse("--evaluate t.yaml --episodes 20 --ns x").options, 0, "/t", "/c.yaml", "");
  EXPECT_FALSE(evaluation.learning());
  EXPECT_EQ("t.yaml", evaluation.load_on_start);
  EXPECT_EQ(20u, evaluation.evaluation_episodes);
  EXPECT_EQ("/x", evaluation.name_space);
  EXPECT_EQ("q_table.yaml", evaluation.q_table_path);
  EXPECT_EQ(std::vector<std::string>({""}), evaluation.suite_folders);  // a config at the root
}

}  // namespace
