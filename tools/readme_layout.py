#!/usr/bin/env python3
"""Writes the Layout table of docs/design.md (the README's docs index links it) from the tree: the
core's modules, the ROS layer's files, the command line, the configuration files, the launch
files, users' scripts and developers' tools, each listed as it is in its folder.
test/unit/core_layout_test.cpp fails when the table and the tree differ, so a new file means running
this again:

  tools/readme_layout.py          # rewrites docs/design.md's Layout table in place
"""
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def stems(*folders):
    names = set()
    for folder in folders:
        path = os.path.join(ROOT, folder)
        names |= {os.path.splitext(f)[0] for f in os.listdir(path) if os.path.isfile(os.path.join(path, f))}
    return sorted(names)


def files(folder):
    path = os.path.join(ROOT, folder)
    return sorted(f for f in os.listdir(path) if os.path.isfile(os.path.join(path, f)))


def quoted(names):
    return ", ".join("`%s`" % n for n in names)


def table():
    rows = [
        ("`include/cartpole_qlearning/common/`, `src/common/`",
         "core layer 1 of 7 (no ROS; each links only layers listed before it here): random numbers, "
         "log lines as values, a wall-clock throttle, the settings its messages point at (named by each front end): "
         + quoted(stems("include/cartpole_qlearning/common", "src/common"))),
        ("`include/cartpole_qlearning/config/`, `src/config/`",
         "core layer 2: settings as tables of keys, whatever holds them (a section's keys listed once drive "
         "reading, refusing unknown keys, writing and the docs check): "
         + quoted(stems("include/cartpole_qlearning/config", "src/config"))),
        ("`include/cartpole_qlearning/io/`, `src/io/`",
         "core layer 3: files (atomic saves, confined paths, size-checked reads, files that grow a line at a time), "
         "YAML documents as parameter sources and sinks, YAML read alike on every yaml-cpp: "
         + quoted(stems("include/cartpole_qlearning/io", "src/io"))),
        ("`include/cartpole_qlearning/simulation/`, `src/simulation/`",
         "core layer 4: the cart-pole's physics (the equations; a MuJoCo model, its own library) and what a real one does: "
         + quoted(stems("include/cartpole_qlearning/simulation", "src/simulation"))),
        ("`include/cartpole_qlearning/learning/`, `src/learning/`",
         "core layer 5: the task, features, the Q-table and its file, the learner, its eligibility traces and "
         "experience replay, a training session, the configuration's sections (their key tables): " + quoted(stems("include/cartpole_qlearning/learning", "src/learning"))),
        ("`include/cartpole_qlearning/protocol/`, `src/protocol/`",
         "core layer 6: the lockstep and controller message protocols, several robots, reset calls: "
         + quoted(stems("include/cartpole_qlearning/protocol", "src/protocol"))),
        ("`include/cartpole_qlearning/application/`, `src/application/`",
         "core layer 7: runs, tables, suites and evaluation, what the nodes and train_headless carry out: "
         + quoted(stems("include/cartpole_qlearning/application", "src/application"))),
        ("`include/cartpole_qlearning/ros/`, `src/ros/`",
         "the ROS layer: the node classes and their mains (`*_node.cpp`), the nodelets (one class template), "
         "message conversions; installed headers only for the node classes and the conversions, the node's "
         "helpers (command publisher, parameter server reader, reset caller and its service probe, "
         "start-up and loggers, launch control) private in `src/ros/`: "
         + quoted(stems("include/cartpole_qlearning/ros", "src/ros"))),
        ("`include/cartpole_qlearning/node_settings/`, `src/node_settings/`",
         "the nodes' settings, read without ROS (their own library, which the nodes and train_headless link): "
         "the controller's and the sim's private parameters checked through a ParameterSource, the robot's pose "
         "and command read once for every node, the names the core's messages give the settings "
         "(~load_on_start, ...), the table folder under ROS_HOME: "
         + quoted(stems("include/cartpole_qlearning/node_settings", "src/node_settings"))),
        ("`src/cli/`", "the command line: `train_headless` (the main only), its options and their rules, one file "
         "per mode and the run they share: " + quoted(stems("src/cli"))),
        ("`msg/`, `srv/`", "`EpisodeStats`, `Reset`, `SaveQTable`, `LoadQTable`"),
        ("`cfg/`", "`Learning.cfg`: the controller's live-tuning fields (dynamic_reconfigure)"),
        ("`config/`", "commented YAML parameters: " + quoted(files("config"))
         + "; `config/robots/`: one profile per public cart-pole, for robot.launch's robot argument"),
        ("`launch/`", "the launch files users type: " + quoted(files("launch")) + "; `launch/include/` holds their parts"),
        ("`urdf/`, `rviz/`", "`cartpole.urdf` (links match the TF frames), `cartpole.rviz`"),
        ("`mjcf/`", "`cartpole.xml`: the cart-pole as a MuJoCo model (config/mujoco_cartpole.yaml; docs/mujoco.md)"),
        ("`docs/`", "the users' pages and pictures (`docs/images/`), each picture made by the command beside it; "
         "`docs/notes/`: the developers' notes (tuning rounds, variants tried, earlier benchmark runs)"),
        ("`test/`", "`unit/<layer>/`: gtests of each core layer (`<layer>_tests`, no ROS) and of its layout; "
         "`node_settings/`: the nodes' settings with YAML text (no master); `ros/`: the ROS layer's message conversions (no master); `cli/`: `train_headless` run as a user runs "
         "it, and its options parsed without a process; `docs/`: the pages' links and parameters; `rostest/`: the nodes' wiring (`*.test` files and their "
         "clients); `support/`: what the tests share; `data/`: their configs; `fuzz/`: fuzzers; "
         "`sanitizer/`: suppressions"),
        ("`bench/`", "benchmarks (Google Benchmark for the core; the lockstep loops against raw TCPROS and "
         "intra-process round trips; the Python anchor; the Suite's swing-up scores beside a hand-written "
         "energy-based reference, `swingup_reference.cpp`, not part of the product)"),
        ("`scripts/`", "what users run: " + quoted(files("scripts"))),
        ("`tools/`", "what developers run (CI, fuzzing, sanitizers, pictures, figures, reference trajectories, the pages' output "
         "blocks checked): "
         + quoted(files("tools"))),
        ("`.ci/`", "`run`: what CI runs (the README's test command in a workspace of its own)"),
    ]
    return "| folder | what is inside |\n| --- | --- |\n" + "".join("| %s | %s |\n" % row for row in rows)


def main():
    page = os.path.join(ROOT, "docs", "design.md")
    text = open(page).read()
    start = text.index("| folder | what is inside |", text.index("## Layout\n"))
    end = text.find("\n## ", start)
    end = len(text) if end < 0 else end + 1
    new = text[:start] + table() + ("\n" if end < len(text) else "") + text[end:]
    open(page, "w").write(new)
    return 0


if __name__ == "__main__":
    sys.exit(main())
