#!/usr/bin/python3
"""The pictures of docs/pictures.md, made again by their commands and checked not blank.

The policy pictures: train_headless trains the default table and config/tiles.yaml's (seed 0),
plot_policy draws each; both actions' colours fill the share of the policy panel that
train_headless --policy says they hold, the value panel is a ramp of colours, and the same table
gives the same bytes: those of docs/images/ on the matplotlib that made them. The nodes diagram:
tools/nodes_diagram reads train.launch's graph from its master; the sim and the controller are
wired as DESIGN.md says; every topic and service of the running graph, and every private
parameter the nodes have on the master, is on docs/nodes.md; and the PNG shows boxes for them.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest
from importlib.machinery import SourceFileLoader
from importlib.util import module_from_spec, spec_from_loader

import numpy
from PIL import Image

PACKAGE = "cartpole_qlearning"
PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PLOT_POLICY = os.path.join(PACKAGE_DIR, "scripts", "plot_policy")
# docs/images/policy_*.png and nodes.png were drawn with Debian 12's matplotlib (CI's); another version lays
# text out otherwise, so only there must the committed pictures be the bytes drawn now.
MATPLOTLIB_OF_THE_DOCS = "3.6.3"
# The titles docs/pictures.md's commands give.
TITLES = {"bins": "config/cartpole.yaml, seed 0", "tiles": "config/tiles.yaml, seed 0"}


def load_script(folder, name):
    loader = SourceFileLoader(name.replace("-", "_"), os.path.join(PACKAGE_DIR, folder, name))
    module = module_from_spec(spec_from_loader(loader.name, loader))
    loader.exec_module(module)
    return module


plot_policy = load_script("scripts", "plot_policy")
nodes_diagram = load_script("tools", "nodes_diagram")


def train_headless():
    import roslib.packages

    found = roslib.packages.find_node(PACKAGE, "train_headless")
    if not found:
        raise unittest.SkipTest("train_headless not built")
    return found[0]


def rgb(hex_colour):
    return tuple(int(hex_colour[i:i + 2], 16) for i in (1, 3, 5))


def share(pixels, colour):
    return float(numpy.all(pixels == numpy.array(colour), axis=2).mean())


class PolicyPictureTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = tempfile.mkdtemp(prefix="docs_pictures_test.")
        cls.env = dict(os.environ, ROS_HOME=cls.work)
        cls.tables = {}
        for name, config in (("bins", "cartpole.yaml"), ("tiles", "tiles.yaml")):
            table = os.path.join(cls.work, name + ".yaml")
            result = subprocess.run([train_headless(), "--config", os.path.join(PACKAGE_DIR, "config", config),
                                     "--seed", "0", "--quiet", "--no-run-folder", "--save", table],
                                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                                    env=cls.env, timeout=120)
            assert result.returncode == 0 and " solved=true " in result.stdout, result.stdout
            cls.tables[name] = table

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.work, ignore_errors=True)

    def draw(self, name, out):
        # The command docs/pictures.md gives, with the picture in the test's folder.
        result = subprocess.run([sys.executable, PLOT_POLICY, self.tables[name], "--title", TITLES[name], "-o", out],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                                env=self.env, timeout=120)
        self.assertEqual(0, result.returncode, result.stdout)
        return result.stdout

    def grid(self, name):
        result = subprocess.run([train_headless(), "--policy", self.tables[name], "--grid", "201"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True,
                                env=self.env, timeout=60)
        self.assertEqual(0, result.returncode, result.stderr)
        return plot_policy.parse_csv(result.stdout, name)

    def check(self, name, ties_expected):
        out = os.path.join(self.work, "policy_%s.png" % name)
        self.draw(name, out)
        with Image.open(out) as image:
            self.assertEqual((1100, 480), image.size)
            pixels = numpy.asarray(image.convert("RGB"))
        policy = self.grid(name)
        points = len(policy.actions)
        left_half, right_half = pixels[:, :550], pixels[:, 550:]
        # Each action's colour fills the policy panel in proportion to the states where it is the
        # greedy one (measured against all the panel's colours: the panel's size does not matter).
        colours = plot_policy.action_colours(policy.action_efforts())
        no_preference = share(left_half, rgb(plot_policy.NO_PREFERENCE_COLOUR))
        panel = sum(share(left_half, rgb(colour)) for colour in colours) + no_preference
        for action, colour in enumerate(colours):
            expected = sum(1 for a, t in zip(policy.actions, policy.ties) if a == action and not t) / points
            self.assertGreater(expected, 0.1, "%s: action %d is greedy almost nowhere" % (name, action))
            found = share(left_half, rgb(colour)) / panel
            self.assertAlmostEqual(found, expected, delta=0.03,
                                   msg="%s: action %d's colour covers %.3f of the policy panel, its states %.3f of the "
                                   "grid" % (name, action, found, expected))
            self.assertLess(share(right_half, rgb(colour)), 0.001, "the action colours are the left panel's alone")
        if ties_expected:
            self.assertGreater(no_preference, 0.02, "%s: the states never learned are not grey" % name)
        else:
            self.assertEqual(0, policy.ties.count(True), "%s: some states of the default table tie" % name)
        # The value panel is a ramp, not a flat colour: many colours of the colourmap.
        panel = right_half[60:420, 60:380].reshape(-1, 3)
        self.assertGreater(len(numpy.unique(panel, axis=0)), 20, "%s: the value panel is blank" % name)
        # Made again, the same bytes: the picture in docs/ can be checked by its command.
        again = os.path.join(self.work, "again_%s.png" % name)
        self.draw(name, again)
        with open(out, "rb") as first, open(again, "rb") as second:
            drawn = first.read()
            self.assertEqual(drawn, second.read(), "%s: the same table drew different bytes" % name)
        import matplotlib

        if matplotlib.__version__ == MATPLOTLIB_OF_THE_DOCS:
            with open(os.path.join(PACKAGE_DIR, "docs", "images", "policy_%s.png" % name), "rb") as committed:
                self.assertEqual(committed.read(), drawn, "docs/images/policy_%s.png is not what its command draws "
                                 "now: run the command in docs/pictures.md again with -o docs/images/policy_%s.png"
                                 % (name, name))

    def test_the_default_tables_policy(self):
        self.check("bins", ties_expected=False)

    def test_the_tile_coded_tables_policy(self):
        self.check("tiles", ties_expected=True)

    def test_what_is_not_a_table_is_refused_without_a_picture(self):
        notes = os.path.join(self.work, "notes.txt")
        with open(notes, "w") as f:
            f.write("not a table\n")
        out = os.path.join(self.work, "notes.png")
        result = subprocess.run([sys.executable, PLOT_POLICY, notes, "-o", out], stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, universal_newlines=True, env=self.env, timeout=60)
        self.assertEqual(2, result.returncode, result.stdout)
        self.assertIn("--policy", result.stdout)
        self.assertFalse(os.path.exists(out))


def page_section(text, node, heading):
    """The text of '### heading' under '## node' in docs/nodes.md."""
    match = re.search(r"^## %s\n(.*?)(?=^## |\Z)" % re.escape(node), text, re.S | re.M)
    if not match:
        return ""
    section = re.search(r"^### %s\n(.*?)(?=^### |\Z)" % re.escape(heading), match.group(1), re.S | re.M)
    return section.group(1) if section else ""


class NodesDiagramTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = tempfile.mkdtemp(prefix="nodes_diagram_test.")
        cls.graph = nodes_diagram.capture(60.0, [], lambda text: print(text, flush=True))
        print(nodes_diagram.describe(cls.graph), flush=True)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.work, ignore_errors=True)

    def test_the_sim_and_the_controller_are_wired_as_the_design_says(self):
        edges = set(self.graph.edges())
        for edge in [("cartpole_sim", "joint_states"), ("joint_states", "qlearning_controller"),
                     ("qlearning_controller", "joint_command"), ("joint_command", "cartpole_sim"),
                     ("cart_effort", "cartpole_sim"), ("qlearning_controller", "episode_stats"),
                     ("cartpole_sim", "/tf")]:
            self.assertIn(edge, edges, nodes_diagram.describe(self.graph))
        self.assertEqual("sensor_msgs/JointState", self.graph.topics["joint_states"])
        services = {node: [s for s, _ in found] for node, found in self.graph.nodes.items()}
        self.assertTrue({"~reset", "~reset_simulation"} <= set(services["cartpole_sim"]), services)
        self.assertTrue({"~save_q_table", "~load_q_table", "~set_parameters"} <= set(services["qlearning_controller"]),
                        services)
        # The master knows no service clients: the reset call comes from the controller's parameter.
        self.assertEqual([("qlearning_controller", "~reset", "cartpole_sim")], self.graph.calls)

    def test_every_topic_and_service_of_the_run_is_on_the_nodes_page(self):
        with open(os.path.join(PACKAGE_DIR, "docs", "nodes.md")) as f:
            text = f.read()
        missing = []
        for node, services in self.graph.nodes.items():
            documented = page_section(text, node, "Services")
            missing += ["%s: service %s" % (node, s) for s, _ in services if "`%s`" % s not in documented]
            for heading, side in (("Published Topics", self.graph.publishers),
                                  ("Subscribed Topics", self.graph.subscribers)):
                documented = page_section(text, node, heading)
                for topic, nodes in side.items():
                    # dynamic_reconfigure's own topics go with ~set_parameters, log once there.
                    reconfigure = topic.startswith(node + "/parameter_")
                    if node in nodes and "`%s`" % topic not in documented and not reconfigure:
                        missing.append("%s: %s %s" % (node, heading.lower(), topic))
        for caller, service, server in self.graph.calls:
            if "`%s/%s`" % (server, service.lstrip("~")) not in page_section(text, caller, "Services Called"):
                missing.append("%s: services called %s/%s" % (caller, server, service.lstrip("~")))
        self.assertEqual([], missing, "docs/nodes.md lacks what the running graph has")

    def test_every_private_parameter_on_the_master_is_on_the_nodes_page(self):
        # What train.launch and the nodes themselves (dynamic_reconfigure, ~run/...) put there.
        with open(os.path.join(PACKAGE_DIR, "docs", "nodes.md")) as f:
            text = f.read()
        self.assertIn("gamma", self.graph.parameters["qlearning_controller"], "the live-tuning fields were not read")
        missing = []
        for node, names in self.graph.parameters.items():
            documented = page_section(text, node, "Parameters") + page_section(text, node, "Dynamic reconfigure")
            missing += ["%s: ~%s" % (node, name) for name in names if "- `~%s` (" % name not in documented]
        self.assertEqual([], missing, "docs/nodes.md lacks parameters the running nodes have")

    def test_the_diagram_is_drawn(self):
        out = os.path.join(self.work, "nodes.png")
        nodes_diagram.draw(self.graph, out, nodes_diagram.title([]))
        with Image.open(out) as image:
            pixels = numpy.asarray(image.convert("RGB"))
        import matplotlib

        if matplotlib.__version__ == MATPLOTLIB_OF_THE_DOCS:
            with open(out, "rb") as drawn, open(os.path.join(PACKAGE_DIR, "docs", "images", "nodes.png"), "rb") as docs:
                self.assertEqual(docs.read(), drawn.read(), "docs/images/nodes.png is not the graph train.launch has "
                                 "now: run tools/nodes_diagram --out docs/images/nodes.png again")
        self.assertGreater(share(pixels, rgb(nodes_diagram.NODE_COLOUR)), 0.01, "no node boxes")
        self.assertGreater(share(pixels, rgb(nodes_diagram.TOPIC_COLOUR)), 0.01, "no topic labels")
        self.assertGreater(share(pixels, (0x44, 0x44, 0x44)), 0.0005, "no arrows")


if __name__ == "__main__":
    import rostest

    rostest.rosrun(PACKAGE, "docs_pictures", "__main__", sys.argv)
