#!/usr/bin/env python3
"""Resets that cannot work, seen from outside (wrong_reset.test). Two lockstep sims serve
cartpole_qlearning/Reset; one controller is told its reset service is a std_srvs/Trigger, the
other is pointed at a service nobody serves. Each trains its first episode (no reset needed), then
its reset call fails at the pole's fall. Each must:
  - say once, as an error, what it found: the type the service serves against the one asked for
    and the parameter to set, or that the service is missing, naming it (the calls are retried
    every 0.2 s meanwhile: each retry finds the same, which is not said again);
  - count no further episode while no reset succeeds, and push no effort after the fall: each new
    state would be answered with 0 and start an episode only inside ~start_region; a lockstep sim
    sends none (it repeats its fallen state, which is left unanswered: the sim waits).
What new states do after a failed reset (a pole spinning through upright) is lockstep_protocol_test's
and robot_dispatch_test's."""
import subprocess
import threading
import time
import unittest

import rospy
import rostest
from cartpole_qlearning.msg import EpisodeStats
from rosgraph_msgs.msg import Log
from sensor_msgs.msg import JointState

WAIT = 60.0  # for the first fall and the error: a loaded 2-core machine
WATCH = 5.0  # then, nothing more is said and no episode counted for this long (25 retries)
WRONG_TYPE = ("reset service /wrong_type/cartpole_sim/reset serves cartpole_qlearning/Reset, not std_srvs/Trigger "
              "as ~reset_service_type asks: set ~reset_service_type to cartpole_qlearning/Reset")
MISSING = "reset service /missing/cartpole_sim/no_such_reset is missing: no node advertises it"


class Robot:
    def __init__(self, ns):
        self.ns = ns
        self.lock = threading.Lock()
        self.episodes = []  # (time, episode number)
        self.commands = []  # (time, effort)
        self.lines = []  # (time, level, text) from this robot's controller
        self.subscribers = [rospy.Subscriber("/%s/episode_stats" % ns, EpisodeStats, self.on_stats),
                            rospy.Subscriber("/%s/joint_command" % ns, JointState, self.on_command)]
        self.sim = None

    def start_sim(self):
        self.sim = subprocess.Popen(["rosrun", "cartpole_qlearning", "cartpole_sim", "__ns:=/" + self.ns,
                                     "__name:=cartpole_sim"])

    def on_stats(self, msg):
        with self.lock:
            self.episodes.append((time.monotonic(), msg.episode))

    def on_command(self, msg):
        with self.lock:
            self.commands.append((time.monotonic(), msg.effort[0] if msg.effort else float("nan")))

    def said(self, words):
        with self.lock:
            return [(t, level, text) for t, level, text in self.lines if words in text]


class WrongResetTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        # Once for both tests: each watches its robot from the start.
        cls.robots = {ns: Robot(ns) for ns in ("wrong_type", "missing")}
        rosout = rospy.Subscriber("/rosout", Log, cls.on_log)  # straight from the nodes
        # Listening to both controllers (and this node: 3 on /rosout) before their sims start: a line
        # said once is not missed.
        subscribers = [rosout] + [s for robot in cls.robots.values() for s in robot.subscribers]
        deadline = time.monotonic() + WAIT
        while time.monotonic() < deadline and not (
                rosout.get_num_connections() >= 3 and all(s.get_num_connections() >= 1 for s in subscribers)):
            time.sleep(0.1)
        for robot in cls.robots.values():
            robot.start_sim()

    @classmethod
    def tearDownClass(cls):
        for robot in cls.robots.values():
            robot.sim.terminate()
            robot.sim.wait()

    @classmethod
    def on_log(cls, msg):
        for ns, robot in cls.robots.items():
            if msg.name == "/%s/qlearning_controller" % ns:
                with robot.lock:
                    robot.lines.append((time.monotonic(), msg.level, msg.msg))

    def check(self, ns, words):
        robot = self.robots[ns]
        deadline = time.monotonic() + WAIT
        while time.monotonic() < deadline and not robot.said(words):
            time.sleep(0.1)
        said = robot.said(words)
        self.assertTrue(said, "%s: not said: %s\nsaid: %s" % (ns, words, [text for _, _, text in robot.lines]))
        said_at, level, text = said[0]
        self.assertEqual(Log.ERROR, level, text)
        self.assertIn("~start_region", text)  # and what happens meanwhile
        with robot.lock:
            episodes = [n for _, n in robot.episodes]
        self.assertEqual([1], episodes, "%s: the first episode, and only it, before the error" % ns)
        time.sleep(WATCH)
        self.assertEqual(1, len(robot.said(words)), "%s: said more than once" % ns)
        self.assertEqual([], robot.said("failed; retrying"), "%s: the call's failure said as well" % ns)
        with robot.lock:
            self.assertEqual([1], [n for _, n in robot.episodes], "%s: episodes counted without a reset" % ns)
            pushes = [effort for t, effort in robot.commands if t > said_at and effort != 0.0]
        self.assertEqual([], pushes, "%s: efforts after the fall" % ns)

    def test_a_service_of_another_type_is_named_with_the_type_it_serves(self):
        self.check("wrong_type", WRONG_TYPE)

    def test_a_service_nobody_serves_is_said_to_be_missing(self):
        self.check("missing", MISSING)


if __name__ == "__main__":
    rospy.init_node("wrong_reset_test")
    rostest.rosrun("cartpole_qlearning", "wrong_reset", WrongResetTest)
