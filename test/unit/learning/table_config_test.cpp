// A table is a controller: the configuration it carries (its trained_with, made by
// trainingConfigText) runs it alone, and a configuration given beside it is checked against it,
// the refusal naming both values and both sources.
#include "cartpole_qlearning/learning/table_config.h"

#include "cartpole_qlearning/io/file_access.h"
#include "cartpole_qlearning/learning/q_table_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <unistd.h>

using namespace cartpole_qlearning;
namespace fs = std::filesystem;

namespace
{
TrainingConfig readText(const std::string& yaml, const std::string& origin = "test.yaml")
{
  return readTrainingConfig(*parseYamlParameters(yaml, origin));
}

TrainingConfig shipped(const std::string& name)
{
  return readTrainingConfig(*loadYamlParameters(std::string(CARTPOLE_CONFIG_DIR) + "/" + name));
}

// A table as a run of `config` saves it: its features and actions, stamped with its step and text.
QTable stampedTable(const TrainingConfig& config)
{
  QTable table(config.agent.featureParams(), config.agent.actions);
  table.tau = config.physics.tau;
  table.trained_with = trainingConfigText(config);
  return table;
}

std::string scratchFile(const std::string& name)
{
  const fs::path dir = fs::temp_directory_path() / ("table_config_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return (dir / name).string();
}
}  // namespace

TEST(TrainingConfigText, EveryShippedConfigReadsBackAsItself)
{
  // (inverted_pendulum_v5.yaml names its model by an environment variable: mujoco_cartpole.yaml stands for it.)
  for (const char* name : {"cartpole.yaml", "robust.yaml", "robust_five_minutes.yaml", "tiles.yaml", "tutorial.yaml",
                           "tutorial_4_states.yaml", "mujoco_cartpole.yaml"})
  {
    const TrainingConfig config = shipped(name);
    const std::string text = trainingConfigText(config);
    const TrainingConfig back = readText(text);
    EXPECT_EQ(text, trainingConfigText(back)) << name;
    // What runs a table, compared field by field besides the text.
    EXPECT_EQ(config.physics.tau, back.physics.tau) << name;
    EXPECT_EQ(config.task.max_episode_steps, back.task.max_episode_steps) << name;
    EXPECT_EQ(config.task.theta_threshold_deg, back.task.theta_threshold_deg) << name;
    EXPECT_EQ(config.agent.featureParams().mismatch(back.agent.featureParams()), "") << name;
    EXPECT_EQ(config.agent.actions, back.agent.actions) << name;
    EXPECT_EQ(config.perturbations.delay_steps_max, back.perturbations.delay_steps_max) << name;
    EXPECT_EQ(config.engine.model, back.engine.model) << name;
  }
}

TEST(TrainingConfigText, TheSameConfigurationIsTheSameTextHoweverItWasWritten)
{
  // The defaults spelt out, in another order and form, or left out: one text.
  EXPECT_EQ(trainingConfigText(readText("")),
            trainingConfigText(readText("{task: {max_episode_steps: 500}, physics: {tau: 2e-2}, learning: "
                                        "{actions: [-10.0, 10]}}")));
  // Anything that differs shows.
  const std::string robust = trainingConfigText(shipped("robust.yaml"));
  EXPECT_NE(trainingConfigText(readText("")), robust);
  EXPECT_NE(std::string::npos, robust.find("max_episode_steps: 200")) << robust;
  EXPECT_NE(std::string::npos, robust.find("features: tiles")) << robust;
  EXPECT_NE(std::string::npos, robust.find("tilings: 8")) << robust;
  EXPECT_NE(std::string::npos, robust.find("tiles: [3, 3, 8, 12]")) << robust;
}

TEST(TrainingConfigText, SaysWhetherASourceHoldsAConfiguration)
{
  EXPECT_FALSE(holdsTrainingConfig(*parseYamlParameters("{robot_description: x}", "ns")));
  EXPECT_TRUE(holdsTrainingConfig(*parseYamlParameters("{task: {max_episode_steps: 9}}", "ns")));
}

TEST(TableConfig, ATableAloneRunsWithTheConfigurationThatTrainedIt)
{
  const TrainingConfig trained = shipped("robust.yaml");
  const std::string path = scratchFile("robust_table.yaml");
  saveQTableFile(stampedTable(trained), path);
  const TableConfig own = tableConfig(loadQTableFile(path), path);
  EXPECT_EQ("", own.defaults_used);
  EXPECT_EQ(trainingConfigText(trained), trainingConfigText(own.config));
  EXPECT_EQ("", tableContradiction(own.config, "its own", loadQTableFile(path), path));
}

TEST(TableConfig, ATableThatDoesNotCarryItsConfigurationRunsWithItsFeaturesOverTheDefaults)
{
  TrainingConfig trained = readText(
      "{learning: {features: tiles, tilings: 4, tiles: [1, 2, 3, 4], previous_action: true, actions: [-5, 0, 5], "
      "lower_bounds: [-1, -2, -0.3, -3], upper_bounds: [1, 2, 0.3, 3]}, physics: {tau: 0.01}}");
  QTable table(trained.agent.featureParams(), trained.agent.actions);
  // A version 2 file: neither step nor configuration.
  const TableConfig v2 = tableConfig(table, "/t/v2.yaml");
  EXPECT_EQ(FeatureKind::Tiles, v2.config.agent.features);
  EXPECT_EQ(4u, v2.config.agent.tilings);
  EXPECT_TRUE(v2.config.agent.previous_action);
  EXPECT_EQ(trained.agent.actions, v2.config.agent.actions);
  EXPECT_EQ("", QTable(v2.config.agent.featureParams(), v2.config.agent.actions).shapeMismatch(table));
  EXPECT_EQ(0.02, v2.config.physics.tau);
  EXPECT_EQ(
      "the table /t/v2.yaml does not say which configuration trained it: the task (thresholds, reward) is the "
      "default one, and so is the step (physics/tau 0.02 s)",
      v2.defaults_used);
  // One that says its step: that step.
  table.tau = 0.01;
  const TableConfig with_step = tableConfig(table, "/t/v3.yaml");
  EXPECT_EQ(0.01, with_step.config.physics.tau);
  EXPECT_EQ(
      "the table /t/v3.yaml does not say which configuration trained it: the task (thresholds, reward) is the "
      "default one",
      with_step.defaults_used);
  // An early version 3 file named its config instead of carrying it: the defaults, said.
  table.trained_with = "config/robust.yaml";
  const TableConfig named = tableConfig(table, "/t/named.yaml");
  EXPECT_EQ(0.01, named.config.physics.tau);
  EXPECT_EQ(0u, named.defaults_used.find("the table's trained_with is not a configuration")) << named.defaults_used;
}

TEST(TableConfig, AContradictionNamesTheConfigsValueAndTheTablesWithBothSources)
{
  // robust.yaml's table (tiles) under the default config (bins): the features differ, and with
  // them everything that shapes them does not compare.
  const QTable robust_table = stampedTable(shipped("robust.yaml"));
  const TrainingConfig defaults = shipped("cartpole.yaml");
  EXPECT_EQ("learning/features is bins in cartpole.yaml but tiles in the table /t/robust_table.yaml",
            tableContradiction(defaults, "cartpole.yaml", robust_table, "/t/robust_table.yaml"));
  const TrainingConfig tiles4 = shipped("tiles.yaml");
  const std::string tilings_said = tableContradiction(tiles4, "tiles.yaml", robust_table, "/t/robust_table.yaml");
  // Every key that differs, the config's value first (the refusal named neither).
  EXPECT_EQ(0u, tilings_said.find("learning/tilings is 4 in tiles.yaml but 8 in the table /t/robust_table.yaml; "
                                  "learning/tiles is [1, 1, 8, 12] in tiles.yaml but [3, 3, 8, 12] in the table "
                                  "/t/robust_table.yaml; "))
      << tilings_said;
  for (const std::string key : {"learning/lower_bounds", "learning/upper_bounds"})
    EXPECT_NE(std::string::npos, tilings_said.find(key + " is ")) << key << ": " << tilings_said;

  // A binned table (robust.yaml's keys before tiles) under the default config: each key named.
  const TrainingConfig trained = readText(
      "{learning: {bins: [3, 3, 8, 12], lower_bounds: [-1, -1, -0.2094, -0.8727], upper_bounds: [1, 1, 0.2094, "
      "0.8727]}}");
  const QTable table = stampedTable(trained);
  const std::string said = tableContradiction(defaults, "cartpole.yaml", table, "/t/binned.yaml");
  for (const std::string key : {"learning/bins", "learning/lower_bounds", "learning/upper_bounds"})
    EXPECT_NE(std::string::npos, said.find(key + " is ")) << key << ": " << said;
  EXPECT_EQ(0u, said.find("learning/bins is [1, 1, 6, 12] in cartpole.yaml but [3, 3, 8, 12] in the table "
                          "/t/binned.yaml; "))
      << said;

  // One at a time, each named with both values.
  TrainingConfig bins = trained;
  bins.agent.discretiser.bins = {{1, 1, 6, 12}};
  ASSERT_EQ((std::array<unsigned, 4>{{3, 3, 8, 12}}), trained.agent.discretiser.bins);
  EXPECT_EQ("learning/bins is [1, 1, 6, 12] in my.yaml but [3, 3, 8, 12] in the table /t/q.yaml",
            tableContradiction(bins, "my.yaml", table, "/t/q.yaml"));
  TrainingConfig previous = trained;
  previous.agent.previous_action = true;
  EXPECT_EQ("learning/previous_action is true in my.yaml but false in the table /t/q.yaml",
            tableContradiction(previous, "my.yaml", table, "/t/q.yaml"));
  TrainingConfig actions = trained;
  actions.agent.actions = {-10.0, 0.0, 10.0};
  EXPECT_EQ("learning/actions is [-10, 0, 10] in my.yaml but [-10, 10] in the table /t/q.yaml",
            tableContradiction(actions, "my.yaml", table, "/t/q.yaml"));
  TrainingConfig tiles = trained;
  tiles.agent.features = FeatureKind::Tiles;
  EXPECT_EQ("learning/features is tiles in my.yaml but bins in the table /t/q.yaml",
            tableContradiction(tiles, "my.yaml", table, "/t/q.yaml"));
  TrainingConfig step = trained;
  step.physics.tau = 0.01;
  EXPECT_EQ("physics/tau is 0.01 in my.yaml but 0.02 in the table /t/q.yaml",
            tableContradiction(step, "my.yaml", table, "/t/q.yaml"));
  TrainingConfig bounds = trained;
  bounds.agent.discretiser.upper[2] = 0.3;
  EXPECT_NE(std::string::npos,
            tableContradiction(bounds, "my.yaml", table, "/t/q.yaml").find("learning/upper_bounds is ["))
      << tableContradiction(bounds, "my.yaml", table, "/t/q.yaml");
  // A table that does not say its step takes any.
  QTable stepless = table;
  stepless.tau = 0.0;
  EXPECT_EQ("", tableContradiction(step, "my.yaml", stepless, "/t/q.yaml"));
  // Other learning settings are no contradiction: the table runs greedily.
  TrainingConfig gamma = trained;
  gamma.agent.gamma = 0.5;
  gamma.task.max_episode_steps = 3000;
  EXPECT_EQ("", tableContradiction(gamma, "my.yaml", table, "/t/q.yaml"));
}

TEST(TableConfig, ATableCarriesItsEnergyCodingAndMirrorAndAConfigWithoutThemIsNamed)
{
  const std::string path = scratchFile("energy_mirror_table.yaml");
  const TrainingConfig trained = readText(
      "{learning: {features: tiles, tiles: [1, 1, 4, 4], energy_tiles: [1, 1, 2, 2], pole_frequency: 3.5, "
      "mirror: true, actions: [-10.0, 0.0, 10.0]}}");
  const std::string text = trainingConfigText(trained);
  EXPECT_NE(std::string::npos, text.find("energy_tiles: [1, 1, 2, 2]")) << text;
  EXPECT_NE(std::string::npos, text.find("mirror: true")) << text;
  saveQTableFile(stampedTable(trained), path);
  const TableConfig own = tableConfig(loadQTableFile(path), path);
  EXPECT_TRUE(own.config.agent.mirror);
  EXPECT_EQ(trained.agent.energy_tiles, own.config.agent.energy_tiles);
  EXPECT_EQ(3.5, own.config.agent.pole_frequency);
  EXPECT_EQ("", tableContradiction(own.config, "its own", loadQTableFile(path), path));
  const TrainingConfig without =
      readText("{learning: {features: tiles, tiles: [1, 1, 4, 4], actions: [-10.0, 0.0, 10.0]}}");
  EXPECT_NE(std::string::npos,
            tableContradiction(without, "c.yaml", loadQTableFile(path), path).find("learning/energy_tiles"));
  // Off (the defaults): not in the text, so that every other table is the file it was.
  const std::string plain = trainingConfigText(without);
  EXPECT_EQ(std::string::npos, plain.find("energy_tiles")) << plain;
  EXPECT_EQ(std::string::npos, plain.find("pole_frequency")) << plain;
  EXPECT_EQ(std::string::npos, plain.find("mirror")) << plain;
}
