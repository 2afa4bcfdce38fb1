#!/usr/bin/python3
"""plot_learning_curve as a user runs it: a CSV becomes a PNG whose pixels show the curve (the
return line rising across the plot, the threshold line, the solved episode marked, epsilon and
alpha below); an empty, missing or foreign file is refused without a picture; a rosbag of the
same episodes gives the same picture; --follow redraws as rows arrive; and the CSV that
train_headless writes draws the run it trained.

The pictures are read back pixel by pixel: the plot areas are found by their black frames, the
lines by the colours the script gives them.
"""
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import numpy

import matplotlib

matplotlib.use("Agg")
import matplotlib.image  # noqa: E402

PACKAGE = "cartpole_qlearning"
HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "..", "..", "scripts", "plot_learning_curve")
HEADER = "episode,robot,steps,episode_return,mean_return_100,epsilon,alpha,terminated,truncated,solved,total_steps,wall_time,gamma"

RETURN_COLOUR = "#1f77b4"
MEAN_COLOUR = "#ff7f0e"
THRESHOLD_COLOUR = "#d62728"
SOLVED_COLOUR = "#2ca02c"
EPSILON_COLOUR = "#9467bd"


def synthetic_episodes(count, solved_from=None):
    """Episodes whose return rises from about 10 to 500 (deterministic), as dicts of the columns."""
    episodes = []
    returns = []
    total = 0
    for e in range(1, count + 1):
        wobble = 15.0 * math.sin(e * 1.7)
        r = max(8.0, min(500.0, 10.0 + 490.0 * (e / (0.8 * count)) ** 2 + wobble))
        r = float(int(r))
        returns.append(r)
        total += int(r)
        window = returns[-100:]
        mean = sum(window) / len(window)
        episodes.append(
            {
                "episode": e,
                "steps": int(r),
                "episode_return": r,
                "mean_return_100": mean,
                "epsilon": max(0.01, 1.0 - e / (0.7 * count)),
                "alpha": 0.1 + 0.4 * math.exp(-e / 100.0),
                "terminated": r < 500.0,
                "truncated": r >= 500.0,
                "solved": solved_from is not None and e >= solved_from,
                "total_steps": total,
            }
        )
    return episodes


def csv_text(episodes):
    lines = [HEADER]
    for x in episodes:
        lines.append(
            "%d,,%d,%r,%r,%r,%r,%s,%s,%s,%d,%.3f,0.99"
            % (
                x["episode"],
                x["steps"],
                x["episode_return"],
                x["mean_return_100"],
                x["epsilon"],
                x["alpha"],
                str(x["terminated"]).lower(),
                str(x["truncated"]).lower(),
                str(x["solved"]).lower(),
                x["total_steps"],
                1.7e9 + x["episode"],
            )
        )
    return "\n".join(lines) + "\n"


def run(args, **kwargs):
    environment = dict(os.environ)
    environment.pop("DISPLAY", None)
    environment.pop("WAYLAND_DISPLAY", None)
    return subprocess.run(
        [sys.executable, SCRIPT] + args,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        universal_newlines=True,
        env=environment,
        timeout=120,
        **kwargs
    )


# --- reading a picture --------------------------------------------------------------------


def load(path):
    return (matplotlib.image.imread(path)[:, :, :3] * 255).round().astype(int)


def runs_of(indices):
    found = []
    for i in indices:
        if found and i == found[-1][1] + 1:
            found[-1][1] = i
        else:
            found.append([i, i])
    return [tuple(g) for g in found]


def plot_areas(image):
    """The inside of each plot area, top to bottom, as (top, bottom, left, right) pixel bounds:
    the frames are the long black lines across the picture."""
    dark = (image < 100).all(axis=2)
    height, width = dark.shape
    rows = runs_of(numpy.nonzero(dark.sum(axis=1) > 0.5 * width)[0])
    columns = runs_of(numpy.nonzero(dark.sum(axis=0) > 0.3 * height)[0])
    assert len(rows) % 2 == 0 and len(columns) == 2, "no plot frames found: rows %s, columns %s" % (rows, columns)
    left, right = columns[0][1] + 1, columns[1][0] - 1
    return [(rows[i][1] + 1, rows[i + 1][0] - 1, left, right) for i in range(0, len(rows), 2)]


def colour_mask(image, area, colour, tolerance=40):
    top, bottom, left, right = area
    rgb = numpy.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)])
    return (abs(image[top : bottom + 1, left : right + 1] - rgb) <= tolerance).all(axis=2)


def line_heights(mask):
    """For each column where the line shows, its mean row (0 at the top of the area)."""
    columns = numpy.nonzero(mask.any(axis=0))[0]
    return columns, numpy.array([numpy.nonzero(mask[:, c])[0].mean() for c in columns])


class PictureTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="plot_learning_curve_test_")

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.dir, name)

    def write(self, name, text):
        with open(self.path(name), "w") as stream:
            stream.write(text)
        return self.path(name)

    def draw(self, args):
        result = run(args)
        self.assertEqual(0, result.returncode, result.stdout)
        return result

    def assert_rising_curve(self, png, solved_at=None, first=1, last=None, rise=0.3):
        """The return and its mean span the top plot area left to right and the mean rises (by at
        least `rise` of the area's height); the threshold is a line across it; the solved episode
        is a vertical line where its episode lies."""
        image = load(png)
        areas = plot_areas(image)
        self.assertEqual(2, len(areas), "expected two plot areas (return; epsilon and alpha)")
        top = areas[0]
        width = top[3] - top[2] + 1
        height = top[1] - top[0] + 1

        returns = colour_mask(image, top, RETURN_COLOUR)
        means = colour_mask(image, top, MEAN_COLOUR)
        self.assertGreater(returns.any(axis=0).sum(), 0.5 * width, "no return line across the plot area")
        columns, heights = line_heights(means)
        self.assertGreater(len(columns), 0.8 * width, "the mean line does not span the plot area")
        # Rising: the right fifth of the mean lies above the left fifth (rows grow downwards).
        fifth = max(1, len(columns) // 5)
        self.assertLess(heights[-fifth:].mean(), heights[:fifth].mean() - rise * height, "the return does not rise")
        # The ends of the curve: the first and the last episode.
        drawn = numpy.nonzero((returns | means).any(axis=0))[0]
        start, end = drawn[0], drawn[-1]

        # The threshold: one horizontal band of red across most of the width, above the early returns.
        red = colour_mask(image, top, THRESHOLD_COLOUR)
        red_rows = numpy.nonzero(red.sum(axis=1) > 0.4 * width)[0]
        self.assertGreater(len(red_rows), 0, "no threshold line")
        self.assertLess(red_rows.max() - red_rows.min(), 4, "the threshold is not one straight line")
        self.assertLess(red_rows.mean(), heights[:fifth].mean())

        green = colour_mask(image, top, SOLVED_COLOUR)
        green_columns = numpy.nonzero(green.sum(axis=0) > 0.8 * height)[0]
        if solved_at is None:
            self.assertEqual(0, len(green_columns), "a solved episode is marked in an unsolved run")
        else:
            self.assertGreater(len(green_columns), 0, "the solved episode is not marked")
            self.assertLess(green_columns.max() - green_columns.min(), 4)
            expected = start + (end - start) * (solved_at - first) / float(last - first)
            self.assertLess(abs(green_columns.mean() - expected), 0.01 * width + 2, "the solved mark is misplaced")

        # Epsilon below, falling.
        bottom = areas[1]
        epsilon_columns, epsilon_heights = line_heights(colour_mask(image, bottom, EPSILON_COLOUR))
        self.assertGreater(len(epsilon_columns), 0.8 * width, "no epsilon line")
        self.assertGreater(epsilon_heights[-1], epsilon_heights[0], "epsilon does not fall")
        return image


class CsvToPngTest(PictureTest):
    def test_a_csv_draws_the_rising_return_the_threshold_and_the_solved_episode(self):
        csv = self.write("episodes.csv", csv_text(synthetic_episodes(300, solved_from=270)))
        result = self.draw([csv, "-o", self.path("curve.png")])
        self.assertIn("300 episodes, solved at episode 270", result.stdout)
        self.assert_rising_curve(self.path("curve.png"), solved_at=270, last=300)

    def test_a_row_being_written_is_left_out(self):
        # A live run's file may end in the middle of a row: the whole rows are drawn.
        csv = self.write("live.csv", csv_text(synthetic_episodes(300, solved_from=270)) + "301,,4")
        result = self.draw([csv, "-o", self.path("live.png")])
        self.assertIn("300 episodes, solved at episode 270", result.stdout)

    def test_a_curve_that_begins_solved_says_solved_by_its_first_episode_not_at_it(self):
        # A --follow started late, or a bag recorded late: the rows from episode 281 on, all solved.
        csv = self.write("late.csv", csv_text(synthetic_episodes(300, solved_from=270)[280:]))
        result = self.draw([csv, "-o", self.path("late.png")])
        self.assertIn("20 episodes, solved by episode 281 (already, where this curve begins)", result.stdout)
        self.assertNotIn("solved at episode", result.stdout)

    def test_an_unsolved_run_has_no_solved_mark_and_the_png_goes_beside_the_csv(self):
        csv = self.write("unsolved.csv", csv_text(synthetic_episodes(150)))
        self.draw([csv])
        self.assert_rising_curve(self.path("unsolved.png"))

    def test_empty_missing_and_foreign_files_are_refused_without_a_picture(self):
        cases = [
            (self.write("header_only.csv", HEADER + "\n"), "no episode"),
            (self.write("zero_bytes.csv", ""), "empty"),
            (self.path("missing.csv"), "cannot read"),
            (self.write("notes.csv", "name,score\nada,3\n"), "no column episode"),
            (self.write("bad_row.csv", HEADER + "\n1,,x,,,,,,,,,\n"), "line 2"),
        ]
        for path, says in cases:
            result = run([path, "-o", self.path("out.png")])
            self.assertEqual(2, result.returncode, "%s: %s" % (path, result.stdout))
            self.assertIn(says, result.stdout, path)
            self.assertFalse(os.path.exists(self.path("out.png")), "%s drew a picture" % path)


class RosbagTest(PictureTest):
    def write_bag(self, name, topics):
        import rosbag
        import rospy
        from cartpole_qlearning.msg import EpisodeStats

        with rosbag.Bag(self.path(name), "w") as bag:
            for topic, episodes in topics:
                for x in episodes:
                    message = EpisodeStats()
                    for field in (
                        "episode", "steps", "episode_return", "mean_return_100", "epsilon", "alpha",
                        "terminated", "truncated", "solved", "total_steps",
                    ):
                        setattr(message, field, x[field])
                    stamp = rospy.Time.from_sec(1000.0 + x["episode"])
                    message.header.stamp = stamp
                    bag.write(topic, message, stamp)
        return self.path(name)

    def test_a_rosbag_of_episode_stats_gives_the_same_curve_as_the_csv(self):
        episodes = synthetic_episodes(300, solved_from=270)
        csv = self.write("episodes.csv", csv_text(episodes))
        self.draw([csv, "-o", self.path("from_csv.png")])
        # The learner's topic first in name order; a robot's topic with other numbers beside it.
        other = synthetic_episodes(40)
        bag = self.write_bag("run.bag", [("/cartpole/robot_0/episode_stats", other), ("/cartpole/episode_stats", episodes)])
        result = self.draw([bag, "-o", self.path("from_bag.png")])
        self.assertIn("drawing /cartpole/episode_stats", result.stdout)
        from_csv = load(self.path("from_csv.png"))
        from_bag = load(self.path("from_bag.png"))
        self.assertEqual(from_csv.shape, from_bag.shape)
        self.assertEqual(0, int((from_csv != from_bag).any(axis=2).sum()), "the rosbag's picture differs from the CSV's")

        # --topic chooses; a topic the bag lacks is refused.
        self.draw([bag, "--topic", "/cartpole/robot_0/episode_stats", "-o", self.path("robot.png")])
        self.assertNotEqual(0, int((load(self.path("robot.png")) != from_bag).any(axis=2).sum()))
        result = run([bag, "--topic", "/nope", "-o", self.path("nope.png")])
        self.assertEqual(2, result.returncode, result.stdout)
        self.assertFalse(os.path.exists(self.path("nope.png")))

    def test_a_rosbag_without_episode_stats_is_refused(self):
        import rosbag
        from std_msgs.msg import String

        with rosbag.Bag(self.path("other.bag"), "w") as bag:
            bag.write("/chatter", String(data="hi"))
        result = run([self.path("other.bag"), "-o", self.path("out.png")])
        self.assertEqual(2, result.returncode, result.stdout)
        self.assertIn("no topic of type cartpole_qlearning/EpisodeStats", result.stdout)
        self.assertFalse(os.path.exists(self.path("out.png")))


class FollowTest(PictureTest):
    def test_follow_redraws_the_png_as_rows_arrive(self):
        episodes = synthetic_episodes(300, solved_from=270)
        text = csv_text(episodes).splitlines(True)
        csv = self.path("growing.csv")
        png = self.path("growing.png")
        # Not there yet: the follower waits for the run to start.
        environment = dict(os.environ)
        environment.pop("DISPLAY", None)
        environment.pop("WAYLAND_DISPLAY", None)
        follower = subprocess.Popen(
            [sys.executable, SCRIPT, "--follow", csv, "-o", png, "--interval", "0.2"],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            universal_newlines=True,
            env=environment,
        )
        try:
            # Each batch of rows in one write: written line by line (writelines goes through an
            # 8 KiB buffer), the follower could draw a part of a batch and the picture checked
            # below would be of fewer rows than the test wrote.
            with open(csv, "w") as stream:
                stream.write(text[0])
                stream.flush()
                time.sleep(1.0)
                self.assertFalse(os.path.exists(png), "a picture with no episode in it")
                stream.write("".join(text[1:121]))
                stream.flush()
                first = self.wait_for_png(png, None)
                # Early on: rising a little, nothing solved yet.
                self.assert_rising_curve(png, rise=0.03)
                stream.write("".join(text[121:]))
                stream.flush()
                second = self.wait_for_png(png, first)
            self.assert_rising_curve(png, solved_at=270, last=300)
            self.assertTrue(follower.poll() is None, "the follower ended by itself")
        finally:
            follower.send_signal(signal.SIGINT)
            output, _ = follower.communicate(timeout=30)
        self.assertIn("300 episodes", output)
        self.assertNotEqual(first, second)

    def wait_for_png(self, png, previous, seconds=60.0):
        deadline = time.time() + seconds
        while time.time() < deadline:
            if os.path.exists(png):
                with open(png, "rb") as stream:
                    data = stream.read()
                if data != previous:
                    return data
            time.sleep(0.1)
        self.fail("the PNG was not (re)drawn within %g s" % seconds)


class TrainHeadlessCurveTest(PictureTest):
    def test_the_readme_command_draws_the_run_train_headless_trained(self):
        import roslib.packages

        train_headless = roslib.packages.find_node(PACKAGE, "train_headless")
        self.assertTrue(train_headless, "train_headless not built")
        csv = self.path("episodes.csv")
        result = subprocess.run(
            [train_headless[0], "--seed", "0", "--quiet", "--no-run-folder", "--stats-csv", csv],
            stdout=subprocess.PIPE,
            universal_newlines=True,
            timeout=300,
        )
        self.assertEqual(0, result.returncode, result.stdout)
        last = result.stdout.strip().splitlines()[-1]
        self.assertTrue(last.startswith("until=solved reached=true solved=true episodes="), last)
        episodes = int(dict(field.split("=") for field in last.split())["episodes"])
        result = self.draw([csv, "-o", self.path("curve.png")])
        self.assertIn("%d episodes, solved at episode %d" % (episodes, episodes), result.stdout)
        self.assert_rising_curve(self.path("curve.png"), solved_at=episodes, last=episodes)


if __name__ == "__main__":
    import rostest

    rostest.rosrun(PACKAGE, "plot_learning_curve", "__main__")
