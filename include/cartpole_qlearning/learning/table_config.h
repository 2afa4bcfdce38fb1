// A table is a controller: what it carries of its training (q_table.h's tau and trained_with) is
// enough to run it without the configuration that trained it, and a configuration given beside
// it is checked against it, naming both.
#pragma once

#include "cartpole_qlearning/learning/q_table.h"
#include "cartpole_qlearning/learning/training_config.h"

#include <string>

namespace cartpole_qlearning
{
// The configuration a table alone runs with.
struct TableConfig
{
  // Its trained_with read as a configuration (else the defaults), with the table's own features,
  // actions and tau over it: the file's header is what numbers its rows.
  TrainingConfig config;
  // "" when the table carries its configuration, else what the run takes from the defaults (a file
  // written before version 3, or one that says only its step).
  std::string defaults_used;
};

// table_path: the file, for what is said.
TableConfig tableConfig(const QTable& table, const std::string& table_path);

// "" when `config` runs `table` as it learnt: the same features (bins or tilings and tiles,
// bounds, previous_action), actions and step (tau, when the table says it); else every
// contradiction with the config's value and the table's ("learning/bins is [3, 3, 6, 12] in
// ORIGIN but [1, 1, 6, 12] in the table PATH; ...").
std::string tableContradiction(const TrainingConfig& config, const std::string& config_origin, const QTable& table,
                               const std::string& table_path);

}  // namespace cartpole_qlearning
