#!/usr/bin/env bash
# Builds the core's unit tests (the core_tests of CMakeLists.txt: everything that needs no ROS)
# with clang-14, AddressSanitizer and UndefinedBehaviorSanitizer, and runs them: any sanitizer
# report fails the run. Debian: clang-14 libclang-rt-14-dev libgtest-dev libyaml-cpp-dev
# libeigen3-dev (scripts/setup.sh installs them).
#
# usage: bash scripts/sanitize.sh [RESULTS_DIR]   (RESULTS_DIR: the gtest JUnit file goes there)
set -euo pipefail
RESULTS=${1:-}
SRC="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
CXX=${SANITIZE_CXX:-clang++-14}
command -v "$CXX" >/dev/null || { echo "sanitize.sh: $CXX not found (Debian: clang-14 libclang-rt-14-dev)" >&2; exit 2; }
WORK=$(mktemp -d "${TMPDIR:-/tmp}/cartpole_sanitize.XXXXXX")
trap 'rm -rf "$WORK"' EXIT

# The sources as CMakeLists.txt lists them for the core library and for core_tests.
list() { sed -n "/^ *$1/,/)/p" "$SRC/CMakeLists.txt" | grep -o "$2/[a-z_]*\.cpp"; }
mapfile -t CORE < <(list 'add_library(${PROJECT_NAME}_core' src)
mapfile -t TESTS < <(list 'catkin_add_gtest(core_tests' test)
echo "[sanitize] building core_tests (${#CORE[@]} core sources, ${#TESTS[@]} test files) with ASan + UBSan"
"$CXX" -std=c++17 -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all \
  -I "$SRC/include" -isystem /usr/include/eigen3 -DCARTPOLE_CONFIG_DIR="\"$SRC/config\"" \
  "${CORE[@]/#/$SRC/}" "${TESTS[@]/#/$SRC/}" -lgtest -lyaml-cpp -pthread -o "$WORK/core_tests"
output=()
[[ -n "$RESULTS" ]] && mkdir -p "$RESULTS" && output=(--gtest_output="xml:$RESULTS/sanitized-core_tests.xml")
echo "[sanitize] running core_tests under ASan + UBSan"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  "$WORK/core_tests" "${output[@]}" --gtest_brief=1
