// The last word on a training's default table. A solved run that was not stopped replaces the
// default table (when it has one) in RunApplication's final save, whose failure the run's final
// line says; read back as evaluate.launch will read it, the file must then hold the session's
// table, else the run fails all the same (train_headless exits 1).
#pragma once

#include "cartpole_qlearning/learning/q_table.h"

#include <string>

namespace cartpole_qlearning
{
// Whether the training's end must have replaced the default table.
bool replacesDefaultTable(bool solved, bool stopped, bool has_default_table);
// Whether the file at `path` holds `table` (its episode and step counts): false when it cannot be
// read.
bool fileHoldsTable(const std::string& path, const QTable& table);

}  // namespace cartpole_qlearning
