#!/bin/sh
# Builds the libFuzzer harness with clang (ASan + UBSan, the library
# instrumented too) in build-fuzz/ and runs it for SECONDS (default 60) from
# the committed corpus. New inputs go to build-fuzz/corpus, never into the
# repository; a crash leaves its reproducer in build-fuzz/ and fails.
#   tests/fuzz/run.sh [SECONDS]
set -eu
seconds="${1:-60}"
root="$(cd "$(dirname "$0")/../.." && pwd)"
build="${LPI_FUZZ_BUILD:-$root/build-fuzz}"
jobs="$(nproc 2>/dev/null || echo 2)"
flags="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_C_FLAGS="$flags" -DCMAKE_CXX_FLAGS="$flags" \
    -DLPI_FUZZ=ON -DLPI_WITH_OPENMP=OFF -DBUILD_TESTING=OFF >/dev/null
cmake --build "$build" -j "$jobs" --target fuzz_api
mkdir -p "$build/corpus"
cd "$build"
# -timeout: one input taking seconds is a hang worth reporting.
ASAN_OPTIONS=detect_leaks=1 "$build/tests/fuzz/fuzz_api" -max_total_time="$seconds" \
    -timeout=10 -rss_limit_mb=2048 -max_len=512 -print_final_stats=1 \
    "$build/corpus" "$root/tests/fuzz/corpus"
