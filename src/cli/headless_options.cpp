#include "headless_options.h"

#include "cartpole_qlearning/learning/delay_predictor.h"
#include "cartpole_qlearning/application/table_store.h"

#include <algorithm>
#include <exception>
#include <limits>

namespace cartpole_qlearning
{
bool parseCount(const std::string& text, std::uint64_t& value)
{
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos)
    return false;
  try
  {
    value = std::stoull(text);
  }
  catch (const std::exception&)
  {
    return false;
  }
  return true;
}

namespace
{
bool isTyped(const HeadlessOptions& options, const std::string& name)
{
  return std::find(options.typed.begin(), options.typed.end(), name) != options.typed.end();
}

// The options the rules name, each with what puts it in effect.
const RuleOption kRobots{"--robots", [](const HeadlessOptions& o) { return o.robots != 1; }};
const RuleOption kNameSpace{"--ns", [](const HeadlessOptions& o) { return isTyped(o, "--ns"); }};
const RuleOption kMaxEpisodes{"--max-episodes", [](const HeadlessOptions& o) { return o.max_episodes != 0; }};
const RuleOption kSave{"--save", [](const HeadlessOptions& o) { return !o.save_path.empty(); }};
const RuleOption kLoad{"--load", [](const HeadlessOptions& o) { return !o.load_path.empty(); }};
const RuleOption kResume{"--resume", [](const HeadlessOptions& o) { return !o.resume_folder.empty(); }};
const RuleOption kCheckpointEvery{"--checkpoint-every", [](const HeadlessOptions& o) { return o.checkpoint_given; }};
// --checkpoint-every 0: no checkpoints, so nothing that needs a run folder.
const RuleOption kCheckpoints{"--checkpoint-every",
                              [](const HeadlessOptions& o) { return o.checkpoint_given && o.checkpoint_every > 0; }};
const RuleOption kNoRunFolder{"--no-run-folder", [](const HeadlessOptions& o) { return o.no_run_folder; }};
const RuleOption kStatsCsv{"--stats-csv", [](const HeadlessOptions& o) { return !o.stats_csv_path.empty(); }};
const RuleOption kReturns{"--returns", [](const HeadlessOptions& o) { return o.print_returns; }};
const RuleOption kGreedyCheck{"--greedy-check", [](const HeadlessOptions& o) { return o.greedy_check > 0; }};
const RuleOption kTrace{"--trace", [](const HeadlessOptions& o) { return o.trace; }};
const RuleOption kEvaluate{"--evaluate", [](const HeadlessOptions& o) { return o.evaluating(); }};
const RuleOption kEpisodes{"--episodes", [](const HeadlessOptions& o) { return o.episodes_given; }};
const RuleOption kMaxSteps{"--max-steps", [](const HeadlessOptions& o) { return o.max_steps_given; }};
const RuleOption kPredictDelay{"--predict-delay", [](const HeadlessOptions& o) { return o.predict_delay_given; }};
const RuleOption kSuite{"--suite", [](const HeadlessOptions& o) { return !o.suite_path.empty(); }};
const RuleOption kReplay{"--replay", [](const HeadlessOptions& o) { return !o.replay_path.empty(); }};
const RuleOption kPolicy{"--policy", [](const HeadlessOptions& o) { return !o.policy_path.empty(); }};
const RuleOption kAverage{"--average", [](const HeadlessOptions& o) { return !o.average_paths.empty(); }};
const RuleOption kQuiet{"--quiet", [](const HeadlessOptions& o) { return o.quiet; }};
const RuleOption kGrid{"--grid", [](const HeadlessOptions& o) { return isTyped(o, "--grid"); }};
const RuleOption kAxes{"--axes", [](const HeadlessOptions& o) { return isTyped(o, "--axes"); }};
const RuleOption kAt{"--at", [](const HeadlessOptions& o) { return isTyped(o, "--at"); }};
const RuleOption kPrevious{"--previous", [](const HeadlessOptions& o) { return isTyped(o, "--previous"); }};

// "a", "a and b", "a, b and c"
std::string namesOf(const std::vector<RuleOption>& options)
{
  std::string names;
  for (std::size_t i = 0; i < options.size(); ++i)
    names += (i == 0 ? "" : i + 1 == options.size() ? " and " : ", ") + std::string(options[i].name);
  return names;
}

// The first rule the options break, as the refusal says it ("" when none).
std::string brokenRule(const HeadlessOptions& options)
{
  for (const OptionRule& rule : headlessOptionRules())
  {
    const bool option_given = rule.option.given(options);
    switch (rule.kind)
    {
      case OptionRule::Kind::Requires:
        for (const RuleOption& other : rule.others)
          if (other.given(options) && !option_given)
            return namesOf(rule.others) + ": " + rule.why;
        break;
      case OptionRule::Kind::Excludes:
      case OptionRule::Kind::OneOf:
        for (const RuleOption& other : rule.others)
          if (option_given && other.given(options))
            return rule.kind == OptionRule::Kind::OneOf
                       ? std::string(rule.option.name) + " and " + other.name + ": " + rule.why
                       : std::string(other.name) + " with " + rule.option.name + ": " + rule.why;
        break;
      case OptionRule::Kind::Alone:
        for (const std::string& typed : options.typed)
          if (option_given && typed != rule.option.name &&
              std::none_of(rule.others.begin(), rule.others.end(),
                           [&](const RuleOption& allowed) { return typed == allowed.name; }))
            return typed + " with " + rule.option.name + ": " + rule.why;
        break;
    }
  }
  return "";
}
}  // namespace

const std::vector<OptionRule>& headlessOptionRules()
{
  using Kind = OptionRule::Kind;
  static const std::vector<OptionRule> rules{
      {Kind::Requires, kPolicy, {kGrid, kAxes, kAt, kPrevious}, "draw a table's policy: give them with --policy TABLE"},
      // The table's file says its features and actions: nothing to train, evaluate or configure.
      {Kind::Alone,
       kPolicy,
       {kGrid, kAxes, kAt, kPrevious, kNameSpace},
       "a policy is drawn from the table alone (its file says its features)"},
      // The tables' files say everything the mean needs: nothing to train, evaluate or configure.
      {Kind::Alone, kAverage, {kSave, kNameSpace, kQuiet}, "--average writes the mean of tables, nothing else"},
      {Kind::Requires, kSave, {kAverage}, "give --save PATH, where the mean of the tables goes"},
      {Kind::OneOf, kLoad, {kResume}, "give one: --resume goes on from a run's own checkpoint"},
      {Kind::Requires, kEvaluate, {kEpisodes}, "counts --evaluate's episodes (training: --max-episodes)"},
      {Kind::Requires,
       kEvaluate,
       {kMaxSteps},
       "is how long --evaluate's episodes are (training's: the config's task/max_episode_steps)"},
      {Kind::Excludes,
       kEvaluate,
       {kLoad, kResume, kSave, kMaxEpisodes, kCheckpointEvery, kNoRunFolder, kStatsCsv, kTrace, kReplay, kGreedyCheck},
       "an evaluation learns nothing and writes nothing"},
      {Kind::Excludes,
       kReplay,
       {kRobots, kMaxEpisodes, kStatsCsv, kLoad, kResume, kCheckpointEvery, kNoRunFolder, kGreedyCheck},
       "a replay learns from its file alone"},
      {Kind::Requires, kEvaluate, {kSuite}, "runs a table: give it with --evaluate TABLE"},
      {Kind::Requires,
       kEvaluate,
       {kPredictDelay},
       "is how a greedy table meets a robot that answers late: give it with --evaluate TABLE (training learns "
       "from the states it observes)"},
      {Kind::Excludes,
       kSuite,
       {kEpisodes, kMaxSteps, kRobots, kReturns},
       "the suite file gives each case's episodes and their length, run on one robot"},
      {Kind::Excludes, kNoRunFolder, {kCheckpoints}, "checkpoints go into the run's folder"},
  };
  return rules;
}

HeadlessCommandLine parseHeadlessOptions(const std::vector<std::string>& args)
{
  HeadlessCommandLine line;
  HeadlessOptions& o = line.options;
  // A value that is not allowed: the refusal names the option, the value and what is.
  const auto refuse = [&line](const std::string& arg, const std::string& value, const std::string& allowed) {
    line.error = arg + " " + value + " is not allowed (" + allowed + ")";
    return line;
  };
  // The options whose value is taken as typed.
  const std::pair<const char*, std::string HeadlessOptions::*> texts[] = {
      {"--replay", &HeadlessOptions::replay_path},
      {"--policy", &HeadlessOptions::policy_path},
      {"--axes", &HeadlessOptions::axes},
      {"--at", &HeadlessOptions::policy_at},
      {"--previous", &HeadlessOptions::previous},
      {"--config", &HeadlessOptions::config_path},
      {"--save", &HeadlessOptions::save_path},
      {"--stats-csv", &HeadlessOptions::stats_csv_path},
      {"--load", &HeadlessOptions::load_path},
      {"--resume", &HeadlessOptions::resume_folder},
      {"--evaluate", &HeadlessOptions::evaluate_path},
      {"--suite", &HeadlessOptions::suite_path},
  };
  for (std::size_t i = 0; i < args.size(); ++i)
  {
    const std::string& arg = args[i];
    const bool has_value = i + 1 < args.size();
    const auto text = std::find_if(std::begin(texts), std::end(texts), [&](const auto& t) { return arg == t.first; });
    if (arg == "--help" || arg == "-h")
    {
      o.help = true;
      return line;
    }
    o.typed.push_back(arg);
    if (arg == "--quiet")
      o.quiet = true;
    else if (arg == "--returns")
      o.print_returns = true;
    else if (arg == "--trace")
      o.trace = true;
    else if (arg == "--no-run-folder")
      o.no_run_folder = true;
    else if (text != std::end(texts) && has_value)
      o.*(text->second) = args[++i];
    else if (arg == "--average" && has_value)
      o.average_paths.push_back(args[++i]);
    else if (arg == "--grid" && has_value)
    {
      if (!parseCount(args[++i], o.grid_points) || o.grid_points < 2 || o.grid_points > kMaxPolicyGridPoints)
        return refuse(arg, args[i], "must be a whole number in [2, " + std::to_string(kMaxPolicyGridPoints) + "]");
    }
    else if (arg == "--ns" && has_value)
    {
      o.name_space = args[++i];
      if (o.name_space.empty() || o.name_space.find("..") != std::string::npos)
        return refuse(arg, "'" + o.name_space + "'", "must be a ROS namespace");
      if (o.name_space.front() != '/')
        o.name_space = "/" + o.name_space;
    }
    else if (arg == "--seed" && has_value)
    {
      std::uint64_t seed = 0;
      if (!parseCount(args[++i], seed))
        return refuse(arg, args[i], "must be a whole number >= 0");
      o.seed = seed;
    }
    else if (arg == "--robots" && has_value)
    {
      if (!parseCount(args[++i], o.robots) || o.robots == 0 || o.robots > 1000)
        return refuse(arg, args[i], "must be a whole number in [1, 1000]");
    }
    else if (arg == "--max-episodes" && has_value)
    {
      if (!parseCount(args[++i], o.max_episodes) || o.max_episodes == 0)
        return refuse(arg, args[i], "must be a whole number >= 1");
    }
    else if (arg == "--checkpoint-every" && has_value)
    {
      o.checkpoint_given = true;
      if (!parseCount(args[++i], o.checkpoint_every))
        return refuse(arg, args[i], "must be a whole number >= 0; 0: no checkpoints");
    }
    else if (arg == "--max-steps" && has_value)
    {
      o.max_steps_given = true;
      if (!parseCount(args[++i], o.max_steps) || o.max_steps == 0 || o.max_steps > std::numeric_limits<int>::max())
        return refuse(arg, args[i],
                      "must be a whole number in [1, " + std::to_string(std::numeric_limits<int>::max()) + "]");
    }
    else if (arg == "--predict-delay" && has_value)
    {
      o.predict_delay_given = true;
      if (std::string(args[++i]) == "auto")
        o.predict_delay = kDelayFoundFromStates;
      else if (!parseCount(args[i], o.predict_delay) || o.predict_delay > kMaxPredictedDelaySteps)
        return refuse(arg, args[i],
                      "must be auto or a whole number in [0, " + std::to_string(kMaxPredictedDelaySteps) + "]");
    }
    else if (arg == "--greedy-check" && has_value)
    {
      if (!parseCount(args[++i], o.greedy_check) || o.greedy_check == 0 || o.greedy_check > 1000)
        return refuse(arg, args[i], "must be a whole number in [1, 1000]");
    }
    else if (arg == "--episodes" && has_value)
    {
      o.episodes_given = true;
      if (!parseCount(args[++i], o.evaluation_episodes) || o.evaluation_episodes == 0)
        return refuse(arg, args[i], "must be a whole number >= 1");
    }
    else
    {
      line.error = "unknown or incomplete argument '" + arg + "'";
      line.usage_after_error = true;
      return line;
    }
  }
  line.error = brokenRule(o);
  if (line.error.empty() && o.average_paths.size() == 1)
    line.error = "--average " + o.average_paths.front() + ": give two tables or more, --average before each";
  return line;
}

SettingNames headlessSettingNames()
{
  return SettingNames([](Setting setting) -> std::string {
    switch (setting)
    {
      case Setting::LoadOnStart:
        return "--load";
      case Setting::LoadOnStartOrigin:  // said before the message: --load or --evaluate
        return "";
      case Setting::TablePath:
        return "--save";
      case Setting::TableFolder:
        return "ROS_HOME, --ns";
      case Setting::SaveService:  // none: a run that cannot save is trained again
        return "";
      case Setting::StatsCsv:
        return "--stats-csv";
      case Setting::Seed:
        return "--seed";
      case Setting::CurveViewer:
        return "rosrun cartpole_qlearning plot_learning_curve --follow";
      case Setting::SuiteEvaluation:
        return "train_headless --evaluate TABLE --suite FILE";
      default:  // the robot's settings: train_headless has no robot of its own to set
        return plainSettingName(setting);
    }
  });
}

RunSettings headlessRunSettings(const HeadlessOptions& options, std::uint64_t seed, const std::string& table_dir,
                                const std::string& config_path, const std::string& package_path)
{
  RunSettings settings;
  settings.mode = options.evaluating() ? RunMode::Evaluate : RunMode::Train;
  settings.seed = seed;
  settings.name_space = options.name_space;
  settings.q_table_dir = table_dir;
  if (!options.save_path.empty())
    settings.q_table_path = options.save_path;
  else if (options.no_run_folder)
    settings.q_table_path.clear();  // no default table either
  else if (settings.learning())
    settings.q_table_path = defaultTableName(config_path);
  settings.load_on_start = options.evaluating() ? options.evaluate_path : options.load_path;
  settings.stats_csv = !options.stats_csv_path.empty() ? options.stats_csv_path : options.no_run_folder ? "none" : "";
  settings.evaluation_episodes = options.evaluation_episodes;
  settings.checkpoint_every = options.no_run_folder ? 0 : options.checkpoint_every;
  settings.save_on_shutdown = !options.no_run_folder;
  settings.run_folder = !options.no_run_folder;
  settings.trace = options.trace;
  // Not told: a greedy run finds the delay from the states, as the controller does.
  settings.predict_delay_steps = options.predict_delay_given ? static_cast<unsigned>(options.predict_delay)
                                 : settings.learning()       ? 0u
                                                             : kDelayFoundFromStates;
  settings.own_absolute_paths = true;
  settings.names = headlessSettingNames();
  // A relative training/suite: beside the config first, then the package's config/.
  const std::string config_folder = config_path.substr(0, config_path.find_last_of('/') + 1);
  settings.suite_folders = {config_folder.empty() ? "." : config_folder.substr(0, config_folder.size() - 1)};
  if (!package_path.empty())
    settings.suite_folders.push_back(package_path + "/config");
  return settings;
}

}  // namespace cartpole_qlearning
