// The task, learning and training sections' tables: each key once, in the order a table's
// trained_with writes them (the physics and perturbations sections: training_config.cpp).
#include "cartpole_qlearning/learning/training_config.h"

#include <limits>
#include <type_traits>

namespace cartpole_qlearning
{
namespace
{
// A member of the params, const or not: field(&TaskParams::x_threshold).
template <typename Member>
auto field(Member member)
{
  return [member](auto& params) -> auto&
  {
    return params.*member;
  };
}

void addSchedule(std::vector<ConfigKey<AgentParams>>& keys, const std::string& name,
                 ScheduleParams AgentParams::*member, const std::string& rate)
{
  const auto schedule = [member](auto& agent) -> auto&
  {
    return agent.*member;
  };
  const auto part = [schedule](auto ScheduleParams::*value) {
    return [ schedule, value ](auto& agent) -> auto&
    {
      return schedule(agent).*value;
    };
  };
  keys.push_back(nameKey<AgentParams>(name + "/schedule", "string: how the " + rate + " falls per episode",
                                      part(&ScheduleParams::type), scheduleTypeFromString));
  keys.push_back(
      plainKey<AgentParams>(name + "/start", "double: the first episode's " + rate, part(&ScheduleParams::start)));
  keys.push_back(plainKey<AgentParams>(name + "/min", "double: the " + rate + "'s floor", part(&ScheduleParams::min)));
  keys.push_back(plainKey<AgentParams>(name + "/decay_episodes", "double, episodes: linear's length to min",
                                       part(&ScheduleParams::decay_episodes)));
  keys.push_back(plainKey<AgentParams>(name + "/decay_rate", "double: exponential's factor an episode",
                                       part(&ScheduleParams::decay_rate)));
  keys.push_back(plainKey<AgentParams>(name + "/log_divisor", "double: the log schedule's divisor",
                                       part(&ScheduleParams::log_divisor)));
}

ConfigKey<TaskParams> solvedRewardKey()
{
  const std::string name = "solved_reward";
  return {name, "string: the reward the solved window counts (default: task/reward's)",
          [name](SectionReader& reader, TaskParams& task) {
            std::string text;
            reader.read(name, text);
            if (text.empty())
              return;
            try
            {
              task.solved_reward = rewardSchemeFromString(text);
            }
            catch (const std::invalid_argument& e)
            {
              reader.fail(name, "'" + text + "'", e.what());
            }
          },
          // Only when set, so that the tables of configs without it stay as they were.
          [name](SectionWriter& writer, const TaskParams& task) {
            if (task.solved_reward)
              writer.word(name, toString(*task.solved_reward));
          }};
}

// alive_quadratic's costs: written with that reward only, so that the other tables stay as they were.
ConfigKey<TaskParams> costKey(const std::string& name, const std::string& doc, double TaskParams::*member)
{
  ConfigKey<TaskParams> key = plainKey<TaskParams>(name, doc, field(member));
  key.write = [name, member](SectionWriter& writer, const TaskParams& task) {
    if (task.reward == RewardScheme::AliveQuadratic)
      writer.write(name, task.*member);
  };
  return key;
}

// Four numbers, one per state value: whole ones (bins, tiles) or any (bounds), as the member is.
template <typename Access>
ConfigKey<AgentParams> dimensionsKey(const std::string& name, const std::string& doc, Access access)
{
  return {name, doc,
          [name, access](SectionReader& reader, AgentParams& agent) {
            auto& values = access(agent);
            readDimensions(reader, name, values, std::is_same_v<std::decay_t<decltype(values[0])>, unsigned>);
          },
          [name, access](SectionWriter& writer, const AgentParams& agent) { writer.write(name, access(agent)); }};
}
// task/kind: CartPole-v1 (the default, not written, so that its tables stay as they were) or one of the
// Control Suite's, which end and score by their own rules: CartPole-v1's keys are refused beside them.
ConfigKey<TaskParams> kindKey()
{
  ConfigKey<TaskParams> key =
      nameKey<TaskParams>("kind", "string: the task", field(&TaskParams::kind), taskKindFromString);
  key.read = [read = key.read](SectionReader& reader, TaskParams& task) {
    read(reader, task);
    if (!isSuiteTask(task.kind))
      return;
    task.max_episode_steps = kSuiteEpisodeSteps;
    for (const char* name : {"x_threshold", "theta_threshold_deg", "reward", "solved_reward", "x_cost", "x_dot_cost"})
      if (reader.has(name))
        throw ConfigError(
            reader.source().describe(reader.key(name)) + " is not allowed with task/kind " + toString(task.kind) +
            " (CartPole-v1's: the Suite's tasks never end on the cart or the angle, and score by their own reward)");
  };
  key.write = [write = key.write](SectionWriter& writer, const TaskParams& task) {
    if (isSuiteTask(task.kind))
      write(writer, task);
  };
  return key;
}

// A key of CartPole-v1's alone: not written beside the Suite's kinds.
ConfigKey<TaskParams> cartPoleKey(ConfigKey<TaskParams> key)
{
  key.write = [write = key.write](SectionWriter& writer, const TaskParams& task) {
    if (!isSuiteTask(task.kind))
      write(writer, task);
  };
  return key;
}

ConfigKey<TaskParams> episodeStepsKey()
{
  ConfigKey<TaskParams> key =
      wholeKey<TaskParams>("max_episode_steps", "int: truncated after this many steps",
                           field(&TaskParams::max_episode_steps), 1, std::numeric_limits<int>::max());
  key.read = [read = key.read](SectionReader& reader, TaskParams& task) {
    read(reader, task);
    // Trained on the Suite's whole episodes (an evaluation or a robot may run others).
    if (isSuiteTask(task.kind) && task.max_episode_steps != kSuiteEpisodeSteps)
      reader.fail("max_episode_steps", std::to_string(task.max_episode_steps),
                  "the Suite's episodes are " + std::to_string(kSuiteEpisodeSteps) + " steps (task/kind " +
                      toString(task.kind) + ")");
  };
  return key;
}
}  // namespace

const ConfigSection<TaskParams>& taskSection()
{
  using T = TaskParams;
  static const ConfigSection<TaskParams> section{
      "task",
      {kindKey(),
       cartPoleKey(plainKey<T>("x_threshold", "double, m: terminated when |x| > this", field(&T::x_threshold))),
       cartPoleKey(plainKey<T>("theta_threshold_deg", "double, deg: terminated when |theta| > this",
                               field(&T::theta_threshold_deg))),
       episodeStepsKey(),
       cartPoleKey(nameKey<T>("reward", "string: what a step is worth", field(&T::reward), rewardSchemeFromString)),
       solvedRewardKey(), costKey("x_cost", "double, 1/m^2: alive_quadratic's cost of x^2 a step", &T::x_cost),
       costKey("x_dot_cost", "double, s^2/m^2: alive_quadratic's cost of x_dot^2 a step", &T::x_dot_cost),
       plainKey<T>("solved_mean_return", "double: solved at this mean return of the window",
                   field(&T::solved_mean_return)),
       wholeKey<T>("solved_window", "int, episodes: the solved window", field(&T::solved_window), 1, 1000000)},
      [](const SectionReader& reader, const TaskParams& task) { reader.check(task.validate()); }};
  return section;
}

const ConfigSection<AgentParams>& learningSection()
{
  using A = AgentParams;
  static const ConfigSection<AgentParams> section = [] {
    ConfigSection<AgentParams> s{
        "learning", {}, [](const SectionReader& reader, const AgentParams& agent) { reader.check(agent.validate()); }};
    const auto bins = [](auto& agent) -> auto&
    {
      return agent.discretiser.bins;
    };
    const auto lower = [](auto& agent) -> auto&
    {
      return agent.discretiser.lower;
    };
    const auto upper = [](auto& agent) -> auto&
    {
      return agent.discretiser.upper;
    };
    s.keys = {
        plainKey<A>("gamma", "double: the discount", field(&A::gamma)),
        plainKey<A>("actions", "list of double, N: the effort of each action", field(&A::actions)),
        nameKey<A>("features", "string: bins or tiles", field(&A::features), featureKindFromString),
        dimensionsKey("bins", "4 ints: bins per state value", bins),
        wholeKey<A>("tilings", "int: tile coding's tilings", field(&A::tilings), 1, kMaxTilings),
        dimensionsKey("tiles", "4 ints: tiles per state value", field(&A::tiles)),
        plainKey<A>("previous_action", "bool: the learner also sees its last action", field(&A::previous_action)),
        dimensionsKey("lower_bounds", "4 doubles: the bins' and tiles' lower bounds", lower),
        dimensionsKey("upper_bounds", "4 doubles: the bins' and tiles' upper bounds", upper),
    };
    // Written only when not the default, so that the tables of configs without them stay as they were.
    ConfigKey<A> lambda =
        plainKey<A>("lambda", "double: Watkins's Q(lambda)'s trace decay, 0 for none", field(&A::lambda));
    lambda.write = [](SectionWriter& writer, const AgentParams& agent) {
      if (agent.lambda != 0.0)
        writer.write("lambda", agent.lambda);
    };
    ConfigKey<A> decision = wholeKey<A>("decision_steps", "int, steps: the physics steps each action is held for",
                                        field(&A::decision_steps), 1, kMaxDecisionSteps);
    decision.write = [](SectionWriter& writer, const AgentParams& agent) {
      if (agent.decision_steps != 1)
        writer.write("decision_steps", agent.decision_steps);
    };
    ConfigKey<A> initial =
        plainKey<A>("initial_value", "double: Q(s, a) before any learning", field(&A::initial_value));
    initial.write = [](SectionWriter& writer, const AgentParams& agent) {
      if (agent.initial_value != 0.0)
        writer.write("initial_value", agent.initial_value);
    };
    ConfigKey<A> second_tiles =
        dimensionsKey("second_tiles", "4 ints: a second tile coding's tiles per state value", field(&A::second_tiles));
    second_tiles.write = [](SectionWriter& writer, const AgentParams& agent) {
      if (agent.featureParams().hasSecondTiles())
        writer.write("second_tiles", agent.second_tiles);
    };
    ConfigKey<A> energy_tiles = dimensionsKey(
        "energy_tiles", "4 ints: a tile coding's tiles per x, x_dot, the pole's energy, theta_dot cos(theta)",
        field(&A::energy_tiles));
    energy_tiles.write = [](SectionWriter& writer, const AgentParams& agent) {
      if (agent.featureParams().hasEnergyTiles())
        writer.write("energy_tiles", agent.energy_tiles);
    };
    ConfigKey<A> pole_frequency =
        plainKey<A>("pole_frequency", "double, rad/s: sqrt(m g l / I) of the pole, for energy_tiles' energy",
                    field(&A::pole_frequency));
    pole_frequency.write = [](SectionWriter& writer, const AgentParams& agent) {
      if (agent.featureParams().hasEnergyTiles())
        writer.write("pole_frequency", agent.pole_frequency);
    };
    ConfigKey<A> replay_updates =
        wholeKey<A>("replay_updates", "int: replayed one-step updates after each decision's own, 0 for none",
                    field(&A::replay_updates), 0, kMaxReplayUpdates);
    replay_updates.write = [](SectionWriter& writer, const AgentParams& agent) {
      if (agent.replay_updates != 0)
        writer.write("replay_updates", agent.replay_updates);
    };
    ConfigKey<A> replay_capacity =
        wholeKey<A>("replay_capacity", "int, transitions: the last transitions replay draws from",
                    field(&A::replay_capacity), 1, kMaxReplayCapacity);
    replay_capacity.write = [](SectionWriter& writer, const AgentParams& agent) {
      if (agent.replay_updates != 0)
        writer.write("replay_capacity", agent.replay_capacity);
    };
    ConfigKey<A> ensemble =
        wholeKey<A>("ensemble", "int: tables learnt side by side, each from its own episodes, the table their mean",
                    field(&A::ensemble), 1, kMaxEnsemble);
    ensemble.write = [](SectionWriter& writer, const AgentParams& agent) {
      if (agent.ensemble != 1)
        writer.write("ensemble", agent.ensemble);
    };
    ConfigKey<A> replay_alpha =
        plainKey<A>("replay_alpha", "double: a replayed update's learning rate, 0 for the episode's alpha",
                    field(&A::replay_alpha));
    replay_alpha.write = [](SectionWriter& writer, const AgentParams& agent) {
      if (agent.replay_updates != 0)
        writer.write("replay_alpha", agent.replay_alpha);
    };
    ConfigKey<A> warp = dimensionsKey("warp", "4 doubles: finer bins and tiles near 0, 1 for uniform", field(&A::warp));
    warp.write = [](SectionWriter& writer, const AgentParams& agent) {
      if (agent.featureParams().warped())
        writer.write("warp", agent.warp);
    };
    s.keys.push_back(warp);
    ConfigKey<A> mirror = plainKey<A>(
        "mirror", "bool: a state with theta < 0 seen as its mirror image, its actions reversed", field(&A::mirror));
    mirror.write = [](SectionWriter& writer, const AgentParams& agent) {
      if (agent.mirror)
        writer.write("mirror", agent.mirror);
    };
    s.keys.push_back(mirror);
    s.keys.push_back(second_tiles);
    s.keys.push_back(energy_tiles);
    s.keys.push_back(pole_frequency);
    s.keys.push_back(lambda);
    s.keys.push_back(initial);
    s.keys.push_back(decision);
    s.keys.push_back(replay_updates);
    s.keys.push_back(replay_capacity);
    s.keys.push_back(replay_alpha);
    s.keys.push_back(ensemble);
    addSchedule(s.keys, "epsilon", &A::epsilon, "exploration rate");
    addSchedule(s.keys, "alpha", &A::alpha, "learning rate");
    ConfigKey<A> names = plainKey<A>("state_names", "list of strings: the table rows' names, then the fallen state's",
                                     field(&A::state_names));
    names.write = [](SectionWriter& writer, const AgentParams& agent) {
      if (!agent.state_names.empty())
        writer.write("state_names", agent.state_names);
    };
    s.keys.push_back(names);
    return s;
  }();
  return section;
}

namespace
{
const char* untilText(TrainUntil until)
{
  return until == TrainUntil::Solved ? "solved" : "suite_passes";
}

ConfigKey<TrainingLimits> untilKey()
{
  return {"until", "string: what ends training: solved or suite_passes",
          [](SectionReader& reader, TrainingLimits& limits) {
            std::string until = untilText(limits.until);
            reader.readChoice("until", until, {"solved", "suite_passes"});
            limits.until = until == "solved" ? TrainUntil::Solved : TrainUntil::SuitePasses;
            if (limits.until == TrainUntil::SuitePasses && (limits.suite_every == 0 || limits.suite == "none"))
              reader.fail(
                  "until", "suite_passes",
                  "needs training/suite_every > 0 and a training/suite: the suite is evaluated during training");
          },
          [](SectionWriter& writer, const TrainingLimits& limits) { writer.word("until", untilText(limits.until)); }};
}
}  // namespace

const ConfigSection<TrainingLimits>& trainingSection()
{
  using L = TrainingLimits;
  static const ConfigSection<TrainingLimits> section = [] {
    ConfigKey<L> suite = plainKey<L>("suite", "string: the robustness suite file, or none", field(&L::suite));
    suite.read = [](SectionReader& reader, TrainingLimits& limits) {
      reader.read("suite", limits.suite);
      if (limits.suite.empty())
        reader.fail("suite", "''", "a suite file, or none");
    };
    ConfigKey<L> best = wholeKey<L>("best_every", "int, episodes: the evaluations that look for the best table",
                                    field(&L::best_every), 0);
    best.read = [](SectionReader& reader, TrainingLimits& limits) {
      reader.read("best_every", limits.best_every, 0);
      // Looked for at evaluations only: its episodes must be some of the suite's.
      if (limits.best_every > 0 && (limits.suite_every == 0 || limits.best_every % limits.suite_every != 0))
        reader.fail("best_every", std::to_string(limits.best_every),
                    "0, or a multiple of training/suite_every (" + std::to_string(limits.suite_every) +
                        "): the best is looked for at evaluations of the suite");
    };
    return ConfigSection<TrainingLimits>{
        "training",
        {wholeKey<L>("max_episodes", "int: stop after this many episodes", field(&L::max_episodes), 1),
         plainKey<L>("stop_when_solved", "bool: stop at the first solved episode", field(&L::stop_when_solved)),
         wholeKey<L>("progress_every", "int, episodes: a progress line every this many", field(&L::progress_every), 0),
         suite,
         wholeKey<L>("suite_every", "int, episodes: also run the suite during training", field(&L::suite_every), 0),
         best, untilKey()},
        nullptr};
  }();
  return section;
}

}  // namespace cartpole_qlearning
