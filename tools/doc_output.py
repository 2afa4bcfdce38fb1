#!/usr/bin/env python3
"""Checks that an output block of a documentation page is what a command printed.

usage: doc_output.py PAGE NAME LOG

The block is the first fenced block after the line `<!-- output: NAME -->` in PAGE (or
`<!-- output: NAME, form -->`). Each of its lines must be found in LOG, in the block's order
(the log may hold other lines between and before them, and a prefix on each line, such as
roslaunch's `[ INFO] [stamp]: `). In a block line:
  - `...` stands for any text (times, paths, lines left out: a line that is only `...` is skipped);
  - `~` stands for a home folder (the docs write ~/.ros, the log has the real path);
  - a line starting with `$ ` is the command, not its output, and is skipped.
With `form` (figures that cannot be reproduced: a real-time run), every number in the block stands
for any number: the lines are checked for their form only.

Exit 0 when every line is found; 1 naming the first line that is not (and the last line
found before it); 2 when the page has no such block. tools/first_hour.sh runs it on the log
of the command the page shows; docs_tests checks that every marked block is run there.
"""
import re
import sys

MARKER = re.compile(r"^<!-- output: (?P<name>[A-Za-z0-9_.-]+)(?P<form>, form)? -->\s*$")
ANSI = re.compile(r"\x1b\[[0-9;]*m")
NUMBER = re.compile(r"[0-9]+(?:\\\.[0-9]+)?")


def block(page, name):
    """The block's lines and whether it is checked for its form only; None when there is none."""
    lines = open(page, encoding="utf-8").read().split("\n")
    for i, line in enumerate(lines):
        match = MARKER.match(line)
        if not match or match.group("name") != name:
            continue
        start = next((j for j in range(i + 1, len(lines)) if lines[j].startswith("```")), None)
        if start is None:
            return None
        end = next((j for j in range(start + 1, len(lines)) if lines[j].startswith("```")), len(lines))
        return lines[start + 1:end], match.group("form") is not None
    return None


def pattern(line, form):
    text = re.escape(line.strip())
    if form:
        text = NUMBER.sub(r"[0-9]+(?:\\.[0-9]+)?", text)
    text = text.replace(r"\.\.\.", ".*")
    # re.escape writes ~ as \~ (Python 3.7-3.11; later ones leave it).
    text = text.replace(r"\~", "~").replace("~", r"\S*")
    return re.compile(text)


def main(argv):
    if len(argv) != 4:
        print(__doc__.strip().split("\n\n")[1], file=sys.stderr)
        return 2
    page, name, log = argv[1:]
    found = block(page, name)
    if found is None:
        print("%s: no block marked <!-- output: %s -->" % (page, name), file=sys.stderr)
        return 2
    wanted, form = found
    output = [ANSI.sub("", line) for line in open(log, encoding="utf-8", errors="replace").read().split("\n")]
    at = 0
    last = None
    for line in wanted:
        if not line.strip() or line.strip() == "..." or line.startswith("$ "):
            continue
        regex = pattern(line, form)
        hit = next((k for k in range(at, len(output)) if regex.search(output[k])), None)
        if hit is None:
            print("%s (%s): not in the output%s: %s" % (page, name, " after '%s'" % last if last else "", line))
            return 1
        at, last = hit + 1, output[hit].strip()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
