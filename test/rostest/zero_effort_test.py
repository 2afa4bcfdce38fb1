#!/usr/bin/env python3
"""The controller commands zero effort when it stops pushing (zero_effort.test): the test plays an
OSKOOO-like robot (Float64 effort on /cart_pole/cart_joint_effort_controller/command, which a
ros_control forward controller would hold forever), then its joint_states stop (~sim_timeout),
then the controller's process gets ~signal: INT (Ctrl-C, roslaunch's first), TERM (what roslaunch sends when SIGINT
has not ended a node in time), or INT to a nodelet's loader, which unloads the controller nodelet from its manager
(zero_effort.test, zero_effort_sigterm.test, zero_effort_nodelet.test)."""
import os
import signal
import threading
import time
import unittest
import xmlrpc.client

import rosgraph
import rospy
import rostest
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

CONTROLLER = "/cartpole/qlearning_controller"


class ZeroEffortTest(unittest.TestCase):
    def setUp(self):
        self.commands = []
        self.lock = threading.Lock()
        self.publishing = threading.Event()
        rospy.Subscriber("/cart_pole/cart_joint_effort_controller/command", Float64, self.on_command)
        self.states = rospy.Publisher("/cart_pole/joint_states", JointState, queue_size=10)
        threading.Thread(target=self.publish_states, daemon=True).start()

    def on_command(self, msg):
        with self.lock:
            self.commands.append((time.monotonic(), msg.data))

    def publish_states(self):
        # Upright and still (the pole reads -0.25 rad upright): episodes begin and run.
        while not rospy.is_shutdown():
            if self.publishing.is_set():
                msg = JointState()
                msg.header.stamp = rospy.Time.now()
                msg.name = ["cart_joint", "pole_joint"]
                msg.position = [0.0, -0.25]
                msg.velocity = [0.0, 0.0]
                self.states.publish(msg)
            time.sleep(0.02)

    def wait_for(self, condition, timeout):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            with self.lock:
                if condition(list(self.commands)):
                    return True
            time.sleep(0.01)
        return False

    def pushing_then_stop(self):
        """Publishes states until the last command is a push, then stops them; returns when."""
        self.publishing.set()
        self.assertTrue(self.wait_for(lambda c: c and c[-1][1] != 0.0, 30.0), "no push commanded")
        self.publishing.clear()
        return time.monotonic()

    def test_zero_after_states_stop_and_after_the_signal(self):
        stopped = self.pushing_then_stop()
        # The freshness guard commands zero a few decision periods after the last state (before
        # ~sim_timeout, 1 s here), and nothing comes after the zero. (30 s bounds a broken run only:
        # the zero is awaited, and a loaded machine may be late with it.)
        self.assertTrue(self.wait_for(lambda c: c[-1][1] == 0.0 and c[-1][0] > stopped and self.quiet(c, 0.5), 30.0),
                        "no zero after the states stopped")

        self.pushing_then_stop()
        self.publishing.set()  # states go on: only the signal stops the pushes
        with self.lock:
            pushes = len(self.commands)
        api = rosgraph.Master("/zero_effort_test").lookupNode(CONTROLLER)
        pid = xmlrpc.client.ServerProxy(api).getPid("/zero_effort_test")[2]
        sig = getattr(signal, "SIG" + rospy.get_param("~signal", "INT"))
        os.kill(pid, sig)
        self.assertTrue(self.wait_for(lambda c: len(c) > pushes and c[-1][1] == 0.0 and self.quiet(c, 0.5), 10.0),
                        "no zero as the last command after " + sig.name)

    @staticmethod
    def quiet(commands, seconds):
        return time.monotonic() - commands[-1][0] > seconds


if __name__ == "__main__":
    rospy.init_node("zero_effort_test")
    rostest.rosrun("cartpole_qlearning", "zero_effort", ZeroEffortTest)
