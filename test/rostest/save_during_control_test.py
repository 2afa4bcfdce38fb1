#!/usr/bin/env python3
"""Services never stall control (save_during_control.test): a driver plays a Float64 robot in front
of robot.launch, states at 50 Hz, while the controller runs the largest table a config may ask for
(20,000,000 values). The test saves that table through ~save_q_table and loads it back through
~load_q_table, each taking seconds, and checks that the commands kept coming at the rate they came
before: the file is written and read on the services' own thread, and the control loop waits only
for the table's copy (a save) or its swap (a load)."""
import os
import shutil
import threading
import time
import unittest

import rospy
import rostest
from cartpole_qlearning.srv import LoadQTable, SaveQTable
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

COMMAND = "/cart_pole/cart_joint_effort_controller/command"
STATES = "/cart_pole/joint_states"
SERVICES = "/cartpole/qlearning_controller/"
PERIOD = 0.02  # the driver's states: 50 Hz, the robot's decision rate
# The longest gap between two commands allowed while a service runs: a few periods and a loaded
# machine's delays. A service on the control path would leave a gap as long as the save or load.
LONGEST_GAP = 0.5


class SaveDuringControlTest(unittest.TestCase):
    def setUp(self):
        self.commands = []
        self.lock = threading.Lock()
        self.ended = False
        rospy.Subscriber(COMMAND, Float64, self.on_command)
        self.states = rospy.Publisher(STATES, JointState, queue_size=10)
        threading.Thread(target=self.drive, daemon=True).start()

    def tearDown(self):
        self.ended = True
        shutil.rmtree(rospy.get_param("~dir"), ignore_errors=True)  # two files of over 100 MB

    def on_command(self, msg):
        with self.lock:
            self.commands.append(time.monotonic())

    def drive(self):
        """An upright pole, stamped now, every period: the controller answers each one."""
        while not rospy.is_shutdown() and not self.ended:
            msg = JointState()
            msg.header.stamp = rospy.Time.now()
            msg.name = ["cart_joint", "pole_joint"]
            msg.position = [0.0, -0.25]  # the profile's pole reads -0.25 rad upright
            msg.velocity = [0.0, 0.0]
            self.states.publish(msg)
            time.sleep(PERIOD)

    def commands_between(self, start, end):
        with self.lock:
            return [t for t in self.commands if start <= t <= end]

    def during(self, what, call):
        """Calls the service and returns (its answer, its seconds), checking the commands meanwhile
        against the second before it."""
        before = time.monotonic()
        time.sleep(1.0)
        start = time.monotonic()
        answer = call()
        end = time.monotonic()
        rate_before = len(self.commands_between(before, start)) / (start - before)
        meanwhile = self.commands_between(start, end)
        self.assertGreater(rate_before, 20.0, "%s: commands came at %.1f Hz before it" % (what, rate_before))
        marks = [start] + meanwhile + [end]
        longest = max(b - a for a, b in zip(marks, marks[1:]))
        rate = len(meanwhile) / (end - start)
        rospy.loginfo("%s took %.2f s: %d commands meanwhile (%.1f Hz; %.1f Hz before), the longest gap %.3f s",
                      what, end - start, len(meanwhile), rate, rate_before, longest)
        # The check can fail only when the call lasts longer than the gap allowed.
        self.assertGreater(end - start, LONGEST_GAP, "%s was too quick to tell anything" % what)
        self.assertLess(longest, LONGEST_GAP, "%s: no command for %.3f s" % (what, longest))
        self.assertGreater(rate, rate_before / 2, "%s: commands at %.1f Hz, %.1f Hz before" % (what, rate, rate_before))
        return answer

    def test_commands_keep_coming_while_the_largest_table_is_saved_and_loaded(self):
        rospy.wait_for_service(SERVICES + "save_q_table", 120.0)
        deadline = time.monotonic() + 60.0
        while time.monotonic() < deadline and len(self.commands_between(0, time.monotonic())) < 100:
            time.sleep(0.1)
        save = rospy.ServiceProxy(SERVICES + "save_q_table", SaveQTable)
        load = rospy.ServiceProxy(SERVICES + "load_q_table", LoadQTable)
        saved = self.during("the save", lambda: save("largest.yaml"))
        self.assertTrue(saved.success, saved.message)
        path = os.path.join(rospy.get_param("~dir"), "largest.yaml")
        self.assertGreater(os.path.getsize(path), 100 * 10 ** 6, "not the largest table")
        loaded = self.during("the load", lambda: load("largest.yaml"))
        self.assertTrue(loaded.success, loaded.message)


if __name__ == "__main__":
    rospy.init_node("save_during_control_test")
    rostest.rosrun("cartpole_qlearning", "save_during_control", SaveDuringControlTest)
