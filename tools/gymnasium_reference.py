#!/usr/bin/env python3
"""Prints reference cart-pole trajectories computed with Gymnasium CartPole-v1's equations.

The step below follows gymnasium/envs/classic_control/cartpole.py (CartPole-v1) operation for
operation, in plain Python floats (IEEE double, as the state is held there), so the test
test/unit/simulation/cartpole_dynamics_test.cpp can compare the core against it without Gymnasium installed.
Run: tools/gymnasium_reference.py  (prints C++ initialisers)
"""
import math

GRAVITY = 9.8
MASSCART = 1.0
MASSPOLE = 0.1
TOTAL_MASS = MASSPOLE + MASSCART
LENGTH = 0.5  # half the pole's length
POLEMASS_LENGTH = MASSPOLE * LENGTH
FORCE_MAG = 10.0
TAU = 0.02


def step(state, action, kinematics="euler"):
    x, x_dot, theta, theta_dot = state
    force = FORCE_MAG if action == 1 else -FORCE_MAG
    costheta = math.cos(theta)
    sintheta = math.sin(theta)
    temp = (force + POLEMASS_LENGTH * theta_dot**2 * sintheta) / TOTAL_MASS
    thetaacc = (GRAVITY * sintheta - costheta * temp) / (
        LENGTH * (4.0 / 3.0 - MASSPOLE * costheta**2 / TOTAL_MASS))
    xacc = temp - POLEMASS_LENGTH * thetaacc * costheta / TOTAL_MASS
    if kinematics == "euler":
        x = x + TAU * x_dot
        x_dot = x_dot + TAU * xacc
        theta = theta + TAU * theta_dot
        theta_dot = theta_dot + TAU * thetaacc
    else:  # semi-implicit euler
        x_dot = x_dot + TAU * xacc
        x = x + TAU * x_dot
        theta_dot = theta_dot + TAU * thetaacc
        theta = theta + TAU * theta_dot
    return (x, x_dot, theta, theta_dot)


def main():
    start = (0.01, -0.02, 0.03, -0.04)
    # A fixed action sequence with both directions and runs of each.
    actions = [1, 1, 0, 1, 0, 0, 0, 1, 1, 1, 0, 1, 0, 0, 1, 1, 0, 0, 0, 1]
    for kinematics in ("euler", "semi_implicit_euler"):
        print("// %s, start %r, actions %r" % (kinematics, start, actions))
        state = start
        for a in actions:
            state = step(state, a, kinematics)
            print("{ %s }," % ", ".join(repr(v) for v in state))


if __name__ == "__main__":
    main()
