#!/usr/bin/env bash
# Builds the libFuzzer targets of test/fuzz/ (the Q-table file parser, the config reader) with
# clang (the release's clang-N, as tools/sanitize.sh), AddressSanitizer and UndefinedBehaviorSanitizer, and runs each for a bounded time
# from the seed corpus in test/fuzz/corpus/. Debian: clang-N and its runtimes, libyaml-cpp-dev
# libeigen3-dev (scripts/setup.sh installs them).
#
# usage: bash tools/fuzz.sh [SECONDS_EACH (default 60)] [RESULTS_DIR]
#   RESULTS_DIR: also write one JUnit file per target there (for catkin_test_results).
#   FUZZ_TARGETS: which targets (default "q_table config"); FUZZ_WORK: the work directory.
# The core is compiled once for all targets and the targets run side by side. Prints per
# target: runs, seconds, corpus size and coverage, and exits 1 if any target found a
# crash (its reproducer is kept under the work directory it names).
set -euo pipefail
SECONDS_EACH=${1:-60}
RESULTS=${2:-}
[[ "$SECONDS_EACH" =~ ^[0-9]+$ ]] || { echo "fuzz.sh: SECONDS_EACH=$SECONDS_EACH must be a whole number" >&2; exit 2; }
SRC="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck source=tools/llvm_toolchain.sh
source "$SRC/tools/llvm_toolchain.sh"
llvm_toolchain || true
CXX=${FUZZ_CXX:-$CLANGXX}
WORK=${FUZZ_WORK:-$(mktemp -d "${TMPDIR:-/tmp}/cartpole_fuzz.XXXXXX")}
mkdir -p "$WORK"

# shellcheck disable=SC2206 # FUZZ_TARGETS is a space-separated list: split on purpose
TARGETS=(${FUZZ_TARGETS:-q_table config})
# Each target's executable: built already (FUZZERS_BUILT), or compiled here.
declare -A FUZZER
TO_BUILD=()
for target in "${TARGETS[@]}"; do
  if [[ -n "${FUZZERS_BUILT:-}" && -x "$FUZZERS_BUILT/${target}_fuzzer" ]]; then
    FUZZER[$target]="$FUZZERS_BUILT/${target}_fuzzer"
    echo "[fuzz] $target: built already (${FUZZER[$target]})"
    # The core's libraries beside it (the devel space's lib/), not the plain build's of the same
    # names that a sourced workspace puts on LD_LIBRARY_PATH, which the loader would take first:
    # uninstrumented, they gave libFuzzer 24 edges to explore instead of a thousand.
    libs=$(cd "$FUZZERS_BUILT/.." && pwd)
    export LD_LIBRARY_PATH="$libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    core=$(ldd "${FUZZER[$target]}" | grep -o '/[^ ]*libcartpole_qlearning_learning\.so' || true)
    [[ "$core" == "$libs/"* ]] ||
      { echo "fuzz.sh: ${FUZZER[$target]} would load the core from '${core:-nowhere}', not from $libs" >&2; exit 2; }
  else
    FUZZER[$target]="$WORK/${target}_fuzzer"
    TO_BUILD+=("$target")
  fi
done
if ((${#TO_BUILD[@]} > 0)); then
  command -v "$CXX" >/dev/null || { echo "fuzz.sh: $CXX not found (Debian: scripts/setup.sh installs the release's clang-N and its runtimes)" >&2; exit 2; }
  # The core layers the parsers live in and rest on (the table file and the config readers are
  # learning's; the config reader asks the engines' registry), as CMakeLists.txt lists them for
  # their libraries. (-ldl: the registry's MuJoCo loader, whose dlopen is libdl's before glibc 2.34.)
  mapfile -t CORE < <(sed -n '/^add_library(${PROJECT_NAME}_\(common\|config\|io\|simulation\|engines\|learning\)/,/)$/p' "$SRC/CMakeLists.txt" |
    grep -o 'src/[a-z_]*/[a-z_]*\.cpp')
  # Line tables only (as tools/sanitize.sh): a report's frames still name function, file and line,
  # for about 10 % less compile time.
  # shellcheck disable=SC2054 # the commas belong to -fsanitize=...
  COMPILE=(-std=c++17 -O1 -gline-tables-only -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined
    -I "$SRC/include" -isystem /usr/include/eigen3)
  # The core is compiled once, for every target (with coverage hooks: fuzzer-no-link), two sources at
  # a time; each target then compiles its own file and links with libFuzzer's main.
  OBJECTS="$WORK/core_objects"
  mkdir -p "$OBJECTS"
  echo "[fuzz] compiling ${#CORE[@]} core sources once (ASan + UBSan, coverage for libFuzzer)"
  SECONDS=0
  compile_one() { "$CXX" "${COMPILE[@]}" -fsanitize=fuzzer-no-link -c "$SRC/$1" -o "$OBJECTS/$(basename "$1" .cpp).o"; }
  running=0
  failed=0
  for source in "${CORE[@]}"; do
    compile_one "$source" &
    if ((++running >= $(nproc))); then
      wait -n || failed=1
      running=$((running - 1))
    fi
  done
  while ((running > 0)); do
    wait -n || failed=1
    running=$((running - 1))
  done
  ((failed == 0)) || { echo "fuzz.sh: the core does not compile with $CXX" >&2; exit 2; }
  echo "[fuzz] compiled in $SECONDS s"
  for target in "${TO_BUILD[@]}"; do
    echo "[fuzz] building $target"
    "$CXX" "${COMPILE[@]}" -fsanitize=fuzzer "$SRC/test/fuzz/${target}_fuzzer.cpp" "$OBJECTS"/*.o -lyaml-cpp -ldl \
      -o "${FUZZER[$target]}"
  done
fi
# The targets run side by side (each on one core, for the same bounded time); their exit statuses
# are kept in files and read afterwards.
echo "[fuzz] running ${TARGETS[*]} side by side for $SECONDS_EACH s (logs in $WORK)"
for target in "${TARGETS[@]}"; do
  corpus="$WORK/corpus_$target"
  mkdir -p "$corpus"
  cp -n "$SRC/test/fuzz/corpus/$target/"* "$corpus/" 2>/dev/null || true
  (
    rc=0
    cd "$WORK" && ASAN_OPTIONS=detect_leaks=1 "${FUZZER[$target]}" -max_total_time="$SECONDS_EACH" \
      -max_len=65536 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 "$corpus" >"$WORK/$target.log" 2>&1 || rc=$?
    echo "$rc" >"$WORK/$target.status"
  ) &
done
wait
status=0
for target in "${TARGETS[@]}"; do
  corpus="$WORK/corpus_$target"
  log="$WORK/$target.log"
  rc=$(cat "$WORK/$target.status" 2>/dev/null || echo 1)
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -n 1 | grep -o '[0-9]*' || echo 0)
  files=$(find "$corpus" -type f | wc -l)
  if ((rc == 0)); then
    echo "[fuzz] $target: ok, $runs runs in $SECONDS_EACH s, corpus $files files, coverage $cov edges"
  else
    status=1
    echo "[fuzz] $target: FOUND A PROBLEM (exit $rc) after $runs runs; reproducer and log in $WORK:"
    grep -E 'ERROR|SUMMARY|runtime error|terminate|Test unit written' "$log" | head -n 8
  fi
  if [[ -n "$RESULTS" ]]; then
    mkdir -p "$RESULTS"
    {
      echo "<?xml version=\"1.0\" encoding=\"UTF-8\"?>"
      echo "<testsuite name=\"fuzz_$target\" tests=\"1\" failures=\"$((rc == 0 ? 0 : 1))\" errors=\"0\">"
      echo "  <testcase classname=\"fuzz\" name=\"${target}_fuzzer_${SECONDS_EACH}s\">"
      ((rc == 0)) || echo "    <failure message=\"libFuzzer exit $rc after $runs runs; see $log\"/>"
      echo "  </testcase>"
      echo "</testsuite>"
    } >"$RESULTS/fuzz-$target.xml"
  fi
done
exit $status
