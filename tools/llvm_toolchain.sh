#!/usr/bin/env bash
# Sourced by tools/sanitize.sh and tools/fuzz.sh: which clang, sanitizer runtimes and
# llvm-symbolizer to use, the ones scripts/setup.sh installed (its "sanitizers" set), never a
# version fixed here: each Debian release has its own (11: clang-11, 12: clang-14, 13: clang-19).
# Sets LLVM_VERSION, CLANG, CLANGXX and LLVM_SYMBOLIZER, in this order of preference:
#   CARTPOLE_LLVM_VERSION (scripts/setup.sh exports what it looked up),
#   the release's default clang (the version its `clang` package depends on: setup.sh's rule),
#   the newest clang++-N installed.
llvm_toolchain() {
  LLVM_VERSION=${CARTPOLE_LLVM_VERSION:-}
  if [ -z "$LLVM_VERSION" ] && command -v apt-cache >/dev/null 2>&1; then
    LLVM_VERSION=$(apt-cache depends clang 2>/dev/null | sed -n 's/^ *Depends: clang-\([0-9][0-9]*\)$/\1/p' | head -n 1)
    command -v "clang++-$LLVM_VERSION" >/dev/null 2>&1 || LLVM_VERSION=
  fi
  if [ -z "$LLVM_VERSION" ]; then
    LLVM_VERSION=$(compgen -c clang++- | sed -n 's/^clang++-\([0-9][0-9]*\)$/\1/p' | sort -n | tail -n 1)
  fi
  CLANG=clang-$LLVM_VERSION
  CLANGXX=clang++-$LLVM_VERSION
  # The one named llvm-symbolizer first: compiler-rt 11 (Debian 11) knows a symbolizer by its file
  # name, refuses llvm-symbolizer-11 ("isn't a known symbolizer") and stops every sanitized process
  # at its start; Debian's llvm-N links the versioned name in /usr/bin to this one.
  LLVM_SYMBOLIZER=/usr/lib/llvm-$LLVM_VERSION/bin/llvm-symbolizer
  [ -x "$LLVM_SYMBOLIZER" ] || LLVM_SYMBOLIZER=$(command -v "llvm-symbolizer-$LLVM_VERSION" || echo "$LLVM_SYMBOLIZER")
  [ -n "$LLVM_VERSION" ]
}

# The ASan runtime (shared) of $CLANGXX: named libclang_rt.asan-x86_64.so, or libclang_rt.asan.so
# where the runtimes sit in a folder per target (LLVM 15 and later may).
asan_runtime() {
  local name path
  for name in libclang_rt.asan-x86_64.so libclang_rt.asan.so; do
    path=$("$CLANGXX" -print-file-name="$name")
    if [ "${path#/}" != "$path" ] && [ -f "$path" ]; then
      echo "$path"
      return 0
    fi
  done
  echo "libclang_rt.asan-x86_64.so"
  return 1
}
