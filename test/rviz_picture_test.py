#!/usr/bin/python3
"""RViz checked by its picture: scripts/rviz_screenshot's pictures of the sim held at theta = +0.2
and -0.2 rad (one run of Xvfb, sim.launch mode:=lockstep rviz:=true and RViz, all its own) must
show a drawn 3D view, the pole's colour, and the pole leaning the way theta says. The expected
lean comes from the geometry alone: the URDF's pole joint axis and pole length, and the Orbit
view of rviz/cartpole.rviz, projected; so a sim whose TF turns the pole the wrong way, a URDF
axis flipped, or a camera looking from behind all fail here."""
import math
import os
import sys
import tempfile
import unittest
from importlib.machinery import SourceFileLoader
from importlib.util import module_from_spec, spec_from_loader

import rostest

PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def load_screenshot_module():
    path = os.path.join(PACKAGE_DIR, "scripts", "rviz_screenshot")
    loader = SourceFileLoader("rviz_screenshot", path)
    module = module_from_spec(spec_from_loader("rviz_screenshot", loader))
    loader.exec_module(module)
    return module


screenshot = load_screenshot_module()

THETA = 0.2
# RViz needs several seconds to start under software OpenGL on a loaded machine; the picture is
# taken as soon as it is drawn, this only bounds a broken run.
TIMEOUT_S = 25.0


class RvizPictureTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = tempfile.mkdtemp(prefix="rviz_picture_test.")
        cls.config = screenshot.read_rviz_config(os.path.join(PACKAGE_DIR, "rviz", "cartpole.rviz"))
        cls.urdf = os.path.join(PACKAGE_DIR, "urdf", "cartpole.urdf")
        states = [(0.0, theta, os.path.join(cls.work, "theta_%+.1f.png" % theta)) for theta in (THETA, -THETA)]
        results = screenshot.take(states, TIMEOUT_S, lambda text: print(text, flush=True))
        cls.pictures = {theta: (complete, measured, out) for (_, theta, out), (complete, measured) in zip(states, results)}

    def check(self, theta):
        complete, measured, out = self.pictures[theta]
        where = " (theta %+.1f: %s; picture %s)" % (theta, measured, out)
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
        self.assertTrue(complete, "RViz's picture was not steady with the pole in it" + where)

    def test_positive_theta_leans_as_the_geometry_says(self):
        self.check(THETA)

    def test_negative_theta_leans_as_the_geometry_says(self):
        self.check(-THETA)


if __name__ == "__main__":
    rostest.rosrun("cartpole_qlearning", "rviz_picture", RvizPictureTest, sys.argv)
