#!/usr/bin/env bash
# The user's two commands on the other Debian releases than CI's: `bash scripts/train.sh` and
# `bash scripts/test.sh`, each in a brand-new root of Debian 11 (bullseye: GCC 10, CMake 3.18, no
# MuJoCo; the nearest to Noetic's Ubuntu 20.04) and Debian 13 (trixie: GCC 14, CMake 3.31), through
# ../shared/tools/fresh_machine.sh. CI runs on Debian 12 (the developer's machine); run this before
# a change to scripts/setup.sh, CMakeLists.txt or code a compiler may take otherwise.
#
# One fresh root per release, where the two commands run one after the other, as a user types them.
# usage (as root, from a clone with the change committed: the roots get `git archive HEAD`):
#   bash tools/check_releases.sh [RELEASE...]          default: bullseye trixie (bookworm: a fresh
#                                                      Debian 12 root, beside CI's own machine)
#   CHECK=train|test|both (default both); LOGS=DIR (default a new folder under /tmp)
#   FRESH_MACHINE=PATH: the fresh_machine.sh to use (default ../shared/tools/fresh_machine.sh
#   beside the clone; without it the check is skipped with a note)
# Prints, per release and command, the wall time, the exit status and the line that matters:
# train.sh's SOLVED line, test.sh's last line ("N passed, N failed, N skipped"); exits 1 if any
# of them is missing. About 10 min per train.sh and 25-45 per test.sh on 2 cores, one root at a
# time (the first root of a release takes a few minutes more to make).
set -uo pipefail
# The whole script is one compound command, read before it runs: bash reads a script as it goes,
# and an edit of this file during an hour-long run would otherwise change what the run does next.
{
SRC="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
FRESH=${FRESH_MACHINE:-$SRC/../shared/tools/fresh_machine.sh}
CHECK=${CHECK:-both}
LOGS=${LOGS:-$(mktemp -d /tmp/check_releases.XXXXXX)}
releases=("$@")
[ "${#releases[@]}" -gt 0 ] || releases=(bullseye trixie)

if [ ! -f "$FRESH" ]; then
  echo "[releases] skipped: no $FRESH (the script that makes fresh Debian roots sits beside the project, in ../shared/tools)"
  exit 0
fi
[ "$(id -u)" -eq 0 ] || { echo "[releases] fresh_machine.sh needs root (debootstrap, chroot, mounts)" >&2; exit 2; }
cd "$SRC" || exit 2
if ! git diff --quiet HEAD 2>/dev/null; then
  echo "[releases] note: uncommitted changes are not checked (the roots get git archive HEAD: $(git rev-parse --short HEAD))"
fi
case "$CHECK" in
  train) commands=(train) ;;
  test) commands=(test) ;;
  both) commands=(train test) ;;
  *) echo "[releases] CHECK=$CHECK: train, test or both" >&2; exit 2 ;;
esac
mkdir -p "$LOGS"
commit=$(git rev-parse --short HEAD)
echo "[releases] commit $commit; logs in $LOGS"

summary=()
status=0
for release in "${releases[@]}"; do
  # One root per release, the commands in the order a user types them (train.sh, then test.sh on
  # the same machine), each timed inside the root.
  inner=". /etc/os-release; echo \"[releases] \$PRETTY_NAME\""
  for command in "${commands[@]}"; do
    inner+="; start=\$(date +%s); bash scripts/$command.sh; rc=\$?"
    inner+="; echo \"[releases] $command.sh exit \$rc after \$((\$(date +%s) - start)) s\""
  done
  # The root goes when its commands end: what a failure needs looking at is printed into the log
  # first (the first three sanitizer reports; the end of the fuzzers' logs, where a crash is
  # described, and of each test log).
  inner+="; for f in \$(ls ~/cartpole_ws/build_sanitize/sanitizer_logs/* 2>/dev/null | head -n 3); do"
  inner+=" echo \"[releases] --- \$f\"; head -n 60 \"\$f\"; done"
  inner+="; for f in /tmp/cartpole_fuzz.*/*.log ~/cartpole_ws/test.log ~/cartpole_ws/sanitize.log; do"
  inner+=" if [ -f \"\$f\" ]; then echo \"[releases] --- the end of \$f\"; tail -n 40 \"\$f\"; fi; done"
  log="$LOGS/$release.log"
  echo "[releases] $release: ${commands[*]/%/.sh} in a fresh root (log: $log)"
  DEBIAN_RELEASE=$release bash "$FRESH" "$inner" >"$log" 2>&1
  for command in "${commands[@]}"; do
    end=$(grep -an "^\[releases\] $command.sh exit " "$log" | tail -n 1)
    rc=$(printf '%s' "$end" | sed -n 's/.* exit \([0-9]*\) after.*/\1/p')
    wall=$(printf '%s' "$end" | sed -n 's/.* after \([0-9]*\) s$/\1/p')
    if [ "$command" = train ]; then
      # The controller's SOLVED line, without roslaunch's colours and time stamp.
      line=$(grep -a 'SOLVED' "$log" | tail -n 1 | sed 's/\x1b\[[0-9;]*m//g; s/^.*\(SOLVED\)/\1/; s/; saved .*//')
      [ -n "$line" ] || line="(no SOLVED line: see $log)"
    else
      # test.sh's last line: the one before its exit line.
      line=$(sed -n "$(( ${end%%:*} - 1 ))p" "$log" 2>/dev/null)
      printf '%s' "$line" | grep -qE '^[0-9]+ passed, 0 failed' || line="${line:-(no last line)} (not all passed: see $log)"
    fi
    case "$line" in "(no"* | *"(not all passed"*) status=1 ;; esac
    [ "${rc:-1}" = 0 ] || status=1
    row=$(printf '%-9s %-6s %3d min %02d s  exit %s  %s' "$release" "$command" $((${wall:-0} / 60)) $((${wall:-0} % 60)) "${rc:-?}" "$line")
    echo "[releases] $row"
    summary+=("$row")
  done
done
echo "[releases] summary (commit $commit):"
printf '  %s\n' "${summary[@]}"
exit "$status"
}
