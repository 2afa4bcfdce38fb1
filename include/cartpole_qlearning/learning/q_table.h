// The Q-table and what it takes to interpret it: the features that number its rows (bins: one
// row per state; tiles: one row of weights per tile, Q the sum over the active tiles), the
// efforts that name its columns, and how much training produced it.
#pragma once

#include "cartpole_qlearning/learning/discretiser.h"
#include "cartpole_qlearning/learning/features.h"

#include <cstdint>
#include <string>
#include <vector>

namespace cartpole_qlearning
{
// The most actions (table columns) a config or a file may have.
constexpr std::size_t kMaxActions = 100;
// The most values (rows times actions) a table may hold: kMaxStates rows of 2 actions, 160 MB in
// memory, whose file (up to some 520 MB) is still read whole under kMaxFileBytes. Without it
// kMaxStates rows of kMaxActions values (8 GB) were allowed, a table no machine here could load.
constexpr std::uint64_t kMaxTableValues = 20000000;
// The largest file a table of `rows` rows of `actions` values may have: its header (up to 1 MiB,
// with the text of the config that trained it) and each row written with every value at its
// longest (24 characters and a separator), twice over for hand-made layouts. A file over it is
// refused before a byte is read.
std::uint64_t maxQTableFileBytes(std::uint64_t rows, std::uint64_t actions);

class QTable
{
public:
  QTable() = default;
  // A table of zeros with one row per discretiser state and one column per action effort.
  QTable(const DiscretiserParams& discretiser, const std::vector<double>& actions);
  // A table of zeros with one row per feature row (state or tile) and one column per action.
  QTable(const FeatureParams& features, const std::vector<double>& actions);

  // Rows: states for bins, tiles of all tilings for tiles.
  std::size_t stateCount() const
  {
    return state_count_;
  }
  std::size_t actionCount() const
  {
    return actions_.size();
  }

  double& at(std::size_t state, std::size_t action)
  {
    return values_[state * actions_.size() + action];
  }
  double at(std::size_t state, std::size_t action) const
  {
    return values_[state * actions_.size() + action];
  }

  // The first action with the largest value (ties go to the lowest index, as numpy's argmax).
  // Inline: a greedy step's choice.
  std::size_t argmax(std::size_t state) const
  {
    const double* row = &values_[state * actions_.size()];
    std::size_t best = 0;
    for (std::size_t a = 1; a < actions_.size(); ++a)
    {
      if (row[a] > row[best])
        best = a;
    }
    return best;
  }
  double max(std::size_t state) const;

  const FeatureParams& features() const
  {
    return features_;
  }
  // The bins and the bounds (the bounds serve tiles too).
  const DiscretiserParams& discretiser() const
  {
    return features_.discretiser;
  }
  const std::vector<double>& actions() const
  {
    return actions_;
  }
  // Row-major: state * actionCount() + action.
  const std::vector<double>& values() const
  {
    return values_;
  }
  // Replaces the values; throws std::invalid_argument unless the size is stateCount() * actionCount().
  void setValues(std::vector<double> values);

  // Training that produced the table, so that a loaded table resumes its schedules.
  std::uint64_t episodes = 0;
  std::uint64_t steps = 0;
  // What it takes to run the table besides its features and actions: the step it learnt [s]
  // (0: not known, a file written before version 3) and the configuration that trained it, a
  // YAML document of its sections (training_config.h's trainingConfigText; "": not known).
  // Every run stamps the tables it saves (TrainingSession::stampTables); table_config.h runs a
  // table with them alone.
  double tau = 0.0;
  std::string trained_with;

  // Empty when the other table has the same features (kind, bins or tilings and tiles, bounds)
  // and actions, else what differs.
  std::string shapeMismatch(const QTable& other) const;

private:
  FeatureParams features_;
  std::vector<double> actions_;
  std::size_t state_count_ = 0;
  std::vector<double> values_;
};

// QTable::shapeMismatch against a table of these features and actions, without making one (a
// table may hold 160 MB of zeros).
std::string tableShapeMismatch(const FeatureParams& features, const std::vector<double>& actions, const QTable& other);

// The mean of tables trained apart (train_headless --average), added one at a time so that only
// one table besides the sum is held: each value the mean of theirs, so each Q the mean of their Qs
// (a tile's weights sum linearly). Tables trained apart err in different states, and where one
// would drop the pole the others outvote it (docs/robust_tables.md). Its counters are their sums
// (it learnt from all their episodes and steps) and it says how to run it as each of them says.
class TableMean
{
public:
  explicit TableMean(QTable first);
  // Throws std::invalid_argument saying what differs, and adds nothing, unless the table has the
  // first one's features, actions, step (tau) and training configuration (trained_with): a mean
  // of tables that learnt different things would not be any configuration's table.
  void add(const QTable& table);
  std::size_t count() const
  {
    return count_;
  }
  // The mean of the tables added (the first alone: itself). Throws std::invalid_argument when a
  // value's sum is not finite (values near the largest double) or a counter would overflow.
  QTable mean() const;

private:
  QTable sum_;  // the first table, its values and counters summed over the tables added
  std::size_t count_ = 1;
  bool counters_overflow_ = false;
};

}  // namespace cartpole_qlearning
