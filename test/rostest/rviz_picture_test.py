#!/usr/bin/python3
"""RViz checked by its picture: tools/rviz_screenshot's pictures of the sim held at theta = +0.2
and -0.2 rad (one run of Xvfb, sim.launch mode:=lockstep rviz:=true and RViz, all its own) must
show a drawn 3D view, the pole's colour, and the pole leaning the way theta says. The expected
lean comes from the geometry alone: the URDF's pole joint axis and pole length, and the Orbit
view of rviz/cartpole.rviz, projected; and, apart from them, the package's convention (theta > 0
toward +x, +x drawn to the right), so a sim whose TF turns the pole the wrong way, a URDF axis
flipped, or a camera looking from behind all fail here. The pictures written are cropped to the
cart-pole and marked (+x, theta), as docs/images/rviz.png is: the robot must fill a good share
of them, with both marks drawn."""
import math
import os
import sys
import unittest
import xml.etree.ElementTree as ElementTree
from importlib.machinery import SourceFileLoader
from importlib.util import module_from_spec, spec_from_loader

import numpy
import rospkg
import rostest
from PIL import Image

PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def load_script(folder, name):
    loader = SourceFileLoader(name, os.path.join(PACKAGE_DIR, folder, name))
    module = module_from_spec(spec_from_loader(name, loader))
    loader.exec_module(module)
    return module


screenshot = load_script("tools", "rviz_screenshot")
rviz_robots = load_script("scripts", "rviz_robots")

THETA = 0.2
# The ceiling on the whole run (Xvfb, the master, the sim, RViz, both pictures), not a wait: each
# picture is taken as soon as RViz shows it, in about 10 s on an idle machine. RViz's start under
# software OpenGL went past the 40 s this once was when the suite ran three tests at a time on two
# cores; rviz_picture.test's time-limit leaves room above it.
TIMEOUT_S = 240.0


class RvizPictureTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        # The pictures stay to be looked at, in one folder rewritten at each run.
        cls.work = os.path.join(rospkg.get_ros_home(), "rviz_picture_test")
        os.makedirs(cls.work, exist_ok=True)
        cls.config = screenshot.read_rviz_config(os.path.join(PACKAGE_DIR, "rviz", "cartpole.rviz"))
        cls.urdf = os.path.join(PACKAGE_DIR, "urdf", "cartpole.urdf")
        states = [(0.0, theta, os.path.join(cls.work, "theta_%+.1f.png" % theta)) for theta in (THETA, -THETA)]
        results = screenshot.take(states, TIMEOUT_S, lambda text: print(text, flush=True))
        cls.pictures = {theta: (complete, measured, out)
                        for (_, theta, out), (complete, measured) in zip(states, results)}

    def check(self, theta):
        complete, measured, out = self.pictures[theta]
        where = " (theta %+.1f: %s; picture %s)" % (theta, measured, out)
        # First: a picture cut short by the ceiling fails as such, not as whatever it showed then.
        self.assertTrue(complete, "RViz did not show the pole, steady, within %g s" % TIMEOUT_S + where)
        left, top, right, bottom = measured.view_box
        self.assertGreater(min(right - left, bottom - top), 200, "no 3D view found in the RViz window" + where)
        # The grid and the robot cover about 6 % of the default view; a blank one has none.
        self.assertGreater(measured.drawn_pixels, 0.01 * measured.view_pixels, "the 3D view is blank" + where)
        self.assertGreaterEqual(measured.pole_pixels, screenshot.MIN_POLE_PIXELS,
                                "the pole's colour is not in the picture: no robot model drawn" + where)
        expected = screenshot.expected_pole_slope(theta, 0.0, self.config, self.urdf)
        # The projected pole of theta = 0.2 rad leans about 0.2 column per row; a line fit through
        # a 3-pixel-wide, 100-row pole measures it to a few percent.
        self.assertEqual(math.copysign(1.0, measured.slope), math.copysign(1.0, expected),
                         "the pole leans the wrong way: expected slope %+.3f column/row" % expected + where)
        self.assertAlmostEqual(measured.slope, expected, delta=0.25 * abs(expected),
                               msg="the pole's lean is not theta's: expected slope %+.3f column/row" % expected + where)
        # Pinned apart from the model and the camera the expectation is computed from (a URDF
        # axis flipped, or a view turned round, would move both alike): in this package's view,
        # x to the right, theta > 0 leans the pole toward +x, its top right of its pivot.
        self.assertEqual(math.copysign(1.0, measured.slope), -math.copysign(1.0, theta),
                         "theta %+.1f should lean the pole's top to the %s" % (theta, "right" if theta > 0 else "left")
                         + where)
        self.check_crop(out, where)

    def check_crop(self, out, where):
        # The written picture: the cart-pole, enlarged, not a window with a small robot in it.
        with Image.open(out) as image:
            picture = image.convert("RGB")
        found = screenshot.robot_box(picture, self.config, self.urdf)
        self.assertIsNotNone(found, "no pole in the cropped picture" + where)
        (left, top, right, bottom), _ = found
        width, height = picture.size
        # The whole window has the robot in about 5 % of its rows x 4 %; cropped, the pole and cart
        # span more than half the height and a tenth of the area.
        self.assertGreater((bottom - top) / height, 0.5, "the cart-pole spans too little of the picture" + where)
        self.assertGreater((right - left) * (bottom - top) / (width * height), 0.08,
                           "the cart-pole fills too little of the picture" + where)
        pixels = numpy.asarray(picture)
        for colour, mark in ((screenshot.THETA_COLOUR, "theta"), (screenshot.MARK_COLOUR, "+x")):
            count = int(numpy.all(pixels == numpy.array(colour), axis=2).sum())
            self.assertGreater(count, 100, "the %s mark is not drawn" % mark + where)

    def test_the_model_and_the_view_keep_the_packages_convention(self):
        # DESIGN: theta > 0 leans the pole toward +x; the README's view shows +x to the right.
        axis, _, top, _ = screenshot.pole_geometry(self.urdf)
        self.assertGreater(screenshot.rotate(top, axis, THETA)[0], 0.0,
                           "the URDF's pole joint turns a positive theta away from +x")
        _, right, _, _ = screenshot.orbit_camera(self.config)
        self.assertGreater(right[0], 0.0, "rviz/cartpole.rviz's view does not show +x to the right")

    def test_positive_theta_leans_as_the_geometry_says(self):
        self.check(THETA)

    def test_negative_theta_leans_as_the_geometry_says(self):
        self.check(-THETA)

    # train.launch robots:=N rviz:=true: RViz on scripts/rviz_robots' config (not pictured here).
    def test_several_robots_get_a_model_each_on_their_prefixed_frames(self):
        displays = rviz_robots.robots_config(self.config, 3)["Visualization Manager"]["Displays"]
        models = [d for d in displays if d["Class"] == "rviz/RobotModel"]
        self.assertEqual([(d["Name"], d["TF Prefix"], d["Robot Description"], d["Enabled"]) for d in models],
                         [("robot_%d" % i, "robot_%d" % i, rviz_robots.DESCRIPTION, True) for i in range(3)])
        others = [d["Class"] for d in displays if d["Class"] != "rviz/RobotModel"]
        self.assertEqual(others, [d["Class"] for d in self.config["Visualization Manager"]["Displays"]
                                  if d["Class"] != "rviz/RobotModel"])

    def test_the_robots_model_has_no_unprefixed_world_link(self):
        with open(self.urdf) as f:
            robot = ElementTree.fromstring(rviz_robots.robot_urdf(f.read()))
        self.assertEqual(sorted(l.get("name") for l in robot.findall("link")), ["cart", "pole"])
        self.assertEqual([(j.get("name"), j.find("parent").get("link")) for j in robot.findall("joint")],
                         [("pole_joint", "cart")])


if __name__ == "__main__":
    rostest.rosrun("cartpole_qlearning", "rviz_picture", RvizPictureTest, sys.argv)
