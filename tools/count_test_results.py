#!/usr/bin/env python3
"""Counts the test cases in a folder of JUnit XML results (gtest and rostest write these) and
prints each failure, then one line "N passed, N failed, N skipped". Exit status 1 when any
failed or none ran.

Each rostest .test file adds one case of its own (rostest-test_*.xml: its fixture nodes launched
and its test node ran) beside the cases of its test node (rosunit-*.xml); both are counted, so
a fixture that fails to launch counts as a failure even when no test case could run.

catkin_test_results is not used for the totals: with googletest 1.12's XML (Debian 12) it
adds the <testsuites> totals to those of each <testsuite> and so counts every test twice.
"""
import glob
import os
import sys
import xml.etree.ElementTree as ElementTree


# Of a failure's message, the lines printed under its FAILED line, and their width.
MESSAGE_LINES = 8
MESSAGE_WIDTH = 300


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else "."
    passed = failed = skipped = 0
    for path in sorted(glob.glob(os.path.join(folder, "**", "*.xml"), recursive=True)):
        try:
            root = ElementTree.parse(path).getroot()
        except ElementTree.ParseError as error:
            print("FAILED %s: unreadable result file (%s)" % (path, error))
            failed += 1
            continue
        cases = root.findall(".//testcase")
        if not cases:
            # A rostest that could not start writes a result with no test case in it.
            print("FAILED %s: no test case ran" % os.path.basename(path))
            failed += 1
            continue
        for case in cases:
            name = "%s.%s" % (case.get("classname", "?"), case.get("name", "?"))
            problems = case.findall("failure") + case.findall("error")
            if problems:
                failed += 1
                message = (problems[0].get("message") or problems[0].text or "").strip().splitlines()
                print("FAILED %s (%s): %s" % (name, os.path.basename(path), message[0] if message else ""))
                # What the check said, not only where: a fresh root or a CI machine is gone by the
                # time anyone reads its log (the first lines, each cut to a screen's width).
                for line in message[1:MESSAGE_LINES]:
                    print("    " + line[:MESSAGE_WIDTH])
            elif case.find("skipped") is not None or case.get("status") == "notrun":
                skipped += 1
            else:
                passed += 1
    print("%d passed, %d failed, %d skipped" % (passed, failed, skipped))
    return 0 if failed == 0 and passed > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
