// A robustness suite: what a table is worth on a robot. Each case is a set of conditions a real
// cart-pole meets (a late command, noisy sensors, other masses, a weaker motor, pushes, wider
// starts, all at once: perturbations.h), run greedily for a number of episodes; a case passes
// when enough of them balance to the step limit. train_headless --evaluate TABLE --suite FILE,
// evaluate.launch and the end of every training run use it.
//
// In parts: the suite file (suite_file.h), the greedy episodes every verdict runs
// (greedy_episodes.h), the runner (suite_runner.h: cases side by side, stopped once decided, the
// probe) and the report (suite_report.h).
#pragma once

#include "cartpole_qlearning/application/suite_file.h"
#include "cartpole_qlearning/application/suite_report.h"
#include "cartpole_qlearning/application/suite_runner.h"
