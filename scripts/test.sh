#!/usr/bin/env bash
# Sets everything up (scripts/setup.sh), builds and runs every test (gtest and rostest), then
# again built with ASan + UBSan (tools/sanitize.sh), and ends with one line
# "N passed, N failed" counting every test case of both.
set -eo pipefail
# Whatever stops this script early (set-up, the build) still ends with the summary line.
trap 'echo "0 passed, 1 failed"' EXIT
# Every package set (tests, MuJoCo, pictures, sanitizers: scripts/setup.sh), and warnings as
# errors: a developer's and CI's build, never a user's (CMake option CARTPOLE_WARNINGS_AS_ERRORS).
export CARTPOLE_PACKAGE_SETS="${CARTPOLE_PACKAGE_SETS:-training testing mujoco pictures sanitizers}"
export CARTPOLE_WARNINGS_AS_ERRORS="${CARTPOLE_WARNINGS_AS_ERRORS:-ON}"
# shellcheck disable=SC1091
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
set -eo pipefail
cd "$CARTPOLE_WS"
# failed_case FILE SUITE CASE MESSAGE: a JUnit file with one failed case, for a part of the run
# that produced no results of its own (so that it counts as a failure, not as tests fewer).
failed_case() {
  mkdir -p "$(dirname "$1")"
  printf '<?xml version="1.0" encoding="UTF-8"?>\n<testsuite name="%s" tests="1" failures="1" errors="0">\n  <testcase classname="%s" name="%s"><failure message="%s"/></testcase>\n</testsuite>\n' \
    "$2" "$2" "$3" "$4" >"$1"
}
rm -rf build/test_results/cartpole_qlearning
echo "[test] catkin_make tests (about 3 minutes on 2 cores), then run_tests (about 8 minutes, three tests at a time); log in $CARTPOLE_WS/test.log"
# A test that does not compile is a failure, not a test fewer.
if ! catkin_make tests -DCMAKE_BUILD_TYPE=Release "-DCARTPOLE_WARNINGS_AS_ERRORS=$CARTPOLE_WARNINGS_AS_ERRORS" >"$CARTPOLE_WS/test.log" 2>&1; then
  grep -E "error|Error" "$CARTPOLE_WS/test.log" | head -n 20
  echo "[test] the tests do not build (log: $CARTPOLE_WS/test.log)"
  exit 1
fi
trap - EXIT
# The sanitized build (tools/sanitize.sh, below) starts now at the lowest priority: it compiles on
# the cores the plain suite leaves idle while its rostests wait on their nodes. When the suite is
# done it is stopped and make takes it up again at the normal priority (below). SANITIZE=0 skips it.
if [ "${SANITIZE:-1}" != 0 ]; then
  echo "[test] meanwhile, at the lowest priority: the ASan + UBSan build (log in $CARTPOLE_WS/sanitize.log)"
  # A session of its own (setsid), so that it can be stopped whole: catkin_make, make, compilers.
  SANITIZE_STEPS=build setsid nice -n 19 bash "$CARTPOLE_SRC/tools/sanitize.sh" >"$CARTPOLE_WS/sanitize.log" 2>&1 &
  sanitize_build_pid=$!
fi
# run_tests keeps going past failing tests; the results files say what failed. Three tests at a
# time with no load limit (catkin_make's default, -jN -lN, ran about one at a time with the two
# cores half idle: a rostest mostly waits on its nodes); TEST_JOBS=1 runs them one by one.
catkin_make run_tests -DCMAKE_BUILD_TYPE=Release "-DCARTPOLE_WARNINGS_AS_ERRORS=$CARTPOLE_WARNINGS_AS_ERRORS" "-j${TEST_JOBS:-3}" >>"$CARTPOLE_WS/test.log" 2>&1 || true
# The README's own check: its commands in order, in a fresh home with a master of its own
# (tools/first_hour.sh); one case per command. It runs beside the sanitized build's end and its
# suite (it shares nothing with them: other home, master and ports), which overlaps one's work
# with the other's waits. Then the fuzzers of test/fuzz/ (table file and config parsers, ASan +
# UBSan, built by the sanitized build), 30 s each beside the sanitized suite; a crash is a failed
# test. FIRST_HOUR=0 and FUZZ_SECONDS=0 skip them.
echo "[test] beside the sanitized half: the README's and docs' commands in a fresh home (tools/first_hour.sh, about 5 minutes; log in $CARTPOLE_WS/first_hour.log), and fuzzing the table file and config parsers (${FUZZ_SECONDS:-30} s each; log in $CARTPOLE_WS/fuzz.log)"
first_hour_pid=""
if [ "${FIRST_HOUR:-1}" != 0 ]; then
  # Its train.sh builds in this workspace (nothing left to build), not a second one from scratch.
  FIRST_HOUR_WORKSPACE="$CARTPOLE_WS" bash "$CARTPOLE_SRC/tools/first_hour.sh" build/test_results/cartpole_qlearning >"$CARTPOLE_WS/first_hour.log" 2>&1 &
  first_hour_pid=$!
fi
fuzz_pid=""
start_fuzzers() { # the fuzzers the sanitized build made, if it did (else fuzz.sh compiles them)
  if [ "${FUZZ_SECONDS:-30}" -gt 0 ]; then
    FUZZERS_BUILT="$CARTPOLE_WS/devel_sanitize/lib/cartpole_qlearning" \
      bash "$CARTPOLE_SRC/tools/fuzz.sh" "${FUZZ_SECONDS:-30}" build/test_results/cartpole_qlearning >"$CARTPOLE_WS/fuzz.log" 2>&1 &
    fuzz_pid=$!
  fi
}
# The whole suite again (every gtest and rostest, the nodes and the nodelet library), built with
# AddressSanitizer, LeakSanitizer and UndefinedBehaviorSanitizer in build_sanitize/ and
# devel_sanitize/. Its results join these as sanitized/sanitized-*.xml, with one case per
# sanitizer report that any process wrote. SANITIZE=0 skips it.
if [ "${SANITIZE:-1}" != 0 ]; then
  echo "[test] the whole suite again under ASan + UBSan: the end of its build, then its run; log in $CARTPOLE_WS/sanitize.log"
  sanitized=build/test_results/cartpole_qlearning/sanitized
  SECONDS=0
  # On a machine busy with other work a build at nice 19 gets next to nothing (a busy loop at nice
  # 0 takes about 98 % of a core from it), and without root a priority cannot be raised again. So
  # the idle-priority build is stopped now and make goes on from where it was at the normal one:
  # what it compiled stays, the files it was compiling are compiled again.
  kill -TERM -- "-$sanitize_build_pid" 2>/dev/null || true
  wait "$sanitize_build_pid" 2>/dev/null || true
  echo "[sanitize] the rest of the build at the normal priority" >>"$CARTPOLE_WS/sanitize.log"
  if SANITIZE_STEPS=build bash "$CARTPOLE_SRC/tools/sanitize.sh" >>"$CARTPOLE_WS/sanitize.log" 2>&1; then
    start_fuzzers
    SANITIZE_STEPS=run bash "$CARTPOLE_SRC/tools/sanitize.sh" "$CARTPOLE_WS/$sanitized" >>"$CARTPOLE_WS/sanitize.log" 2>&1 || sanitize_failed=1
  else
    start_fuzzers
    sanitize_failed=1
  fi
  if [ -n "${sanitize_failed:-}" ]; then
    grep -E "error|Error" "$CARTPOLE_WS/sanitize.log" | head -n 20
    tail -n 10 "$CARTPOLE_WS/sanitize.log"
    failed_case "$sanitized/sanitized-build-failed.xml" sanitized_build build_asan_ubsan "the sanitized build failed; see $CARTPOLE_WS/sanitize.log"
  fi
  grep -E "^\[sanitize\] (built|ran|[0-9]+ sanitizer report)" "$CARTPOLE_WS/sanitize.log" || true
  echo "[test] ASan + UBSan suite: $SECONDS s"
else
  start_fuzzers
fi

SECONDS=0
[ -z "$first_hour_pid" ] || wait "$first_hour_pid" || true
[ -z "$fuzz_pid" ] || wait "$fuzz_pid" || true
echo "[test] waited $SECONDS s more for first_hour.sh and the fuzzers"
if [ "${FUZZ_SECONDS:-30}" -gt 0 ]; then
  grep -E "^\[fuzz\] .*(ok|FOUND|compiled|built already)" "$CARTPOLE_WS/fuzz.log" || true
  if ! ls build/test_results/cartpole_qlearning/fuzz-*.xml >/dev/null 2>&1; then
    tail -n 20 "$CARTPOLE_WS/fuzz.log"
    failed_case build/test_results/cartpole_qlearning/fuzz-aborted.xml fuzz fuzz_script "the fuzzers did not run; see $CARTPOLE_WS/fuzz.log"
  fi
fi
if [ "${FIRST_HOUR:-1}" != 0 ]; then
  grep -E "^\[first-hour\] +([0-9.]+ s|[0-9]+ passed)" "$CARTPOLE_WS/first_hour.log" | grep -E "FAIL|passed" || true
  if [ ! -s build/test_results/cartpole_qlearning/first_hour.xml ]; then
    tail -n 30 "$CARTPOLE_WS/first_hour.log"
    failed_case build/test_results/cartpole_qlearning/first_hour-aborted.xml first_hour first_hour_script "see $CARTPOLE_WS/first_hour.log"
  fi
fi
if ! ls build/test_results/cartpole_qlearning/*.xml >/dev/null 2>&1; then
  tail -n 60 "$CARTPOLE_WS/test.log"
  echo "[test] no test results were produced (the build of the tests failed?)"
  echo "0 passed, 1 failed"
  exit 1
fi
# Prints each failure, then the last line: "N passed, N failed, N skipped".
exec /usr/bin/env python3 "$CARTPOLE_SRC/tools/count_test_results.py" build/test_results/cartpole_qlearning
