#!/usr/bin/env bash
# Builds the libFuzzer targets with clang-14 (AddressSanitizer, UndefinedBehaviorSanitizer) in
# build-fuzz/ and runs each for SECONDS (default 30) on a copy of its seed corpus. A finding
# (crash, sanitizer report, leak, > 1 s on one input, > 2 GB) stops that target with exit 1 and
# leaves its input in fuzz/findings/TARGET/: fix it, then commit the input to
# fuzz/regressions/TARGET/ (the test suite replays it).
#   fuzz/run.sh [SECONDS] [TARGET...]
# MMH_FUZZ_TIMEOUT (seconds, default 1): the time one input may take. libFuzzer measures it on the
# wall clock, so on a machine loaded far beyond its cores a starved process can exceed 1 s on an
# input that takes milliseconds (replay a timeout alone to tell): raise it there.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-30}"
shift || true
build_dir="${MMH_FUZZ_BUILD_DIR:-$root/build-fuzz}"
targets=("$@")
if [[ ${#targets[@]} -eq 0 ]]; then
  # every target: fuzz/TARGET_fuzzer.cc
  for f in "$root"/fuzz/*_fuzzer.cc; do t="${f##*/}"; targets+=("${t%_fuzzer.cc}"); done
fi
if [[ ! -f "$build_dir/CMakeCache.txt" ]]; then
  cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_COMPILER=clang++-14 -DMMH_BUILD_FUZZ=ON -DMMH_BUILD_BENCH=OFF \
    ${CMAKE_CXX_COMPILER_LAUNCHER:+-DCMAKE_CXX_COMPILER_LAUNCHER=$CMAKE_CXX_COMPILER_LAUNCHER} \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g -fno-omit-frame-pointer -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
fi
ninja -C "$build_dir" -j "${MMH_FUZZ_JOBS:-$(nproc)}" "${targets[@]/#/fuzz_}" >/dev/null
status=0
for t in "${targets[@]}"; do
  work="$build_dir/fuzz-corpus/$t"
  findings="$root/fuzz/findings/$t"
  mkdir -p "$work" "$findings"
  cp -n "$root/fuzz/corpus/$t/"* "$work/" 2>/dev/null || true
  echo "fuzz: $t for ${seconds} s"
  # (The LeakSanitizer suppressions name third-party libraries only: tools/sanitizer/lsan.supp.)
  if ! UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      LSAN_OPTIONS="suppressions=$root/tools/sanitizer/lsan.supp:print_suppressions=0" \
      "$build_dir/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout="${MMH_FUZZ_TIMEOUT:-1}" -rss_limit_mb=2048 \
      -max_len=65536 -print_final_stats=1 -artifact_prefix="$findings/" "$work" \
      "$root/fuzz/regressions/$t" 2>"$build_dir/fuzz-$t.log"; then
    echo "fuzz: $t FOUND a problem: see $build_dir/fuzz-$t.log and $findings/" >&2
    status=1
  fi
  grep -E "^stat::number_of_executed_units|^stat::peak_rss_mb|^#[0-9]+.*DONE" \
    "$build_dir/fuzz-$t.log" | sed "s/^/  /" || true
done
exit $status
