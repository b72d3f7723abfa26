#!/bin/sh
# Builds the libFuzzer harnesses with clang (ASan + UBSan, the library
# instrumented too) in build-fuzz/ and runs them from their committed corpora
# for SECONDS in all (default 60): half to fuzz_api (the API surface), a
# quarter each to fuzz_checkpoint (the checkpoint decoder) and fuzz_npy (the
# lpi tool's .npy reader). New inputs go to build-fuzz/corpus*, never into the
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
cmake --build "$build" -j "$jobs" --target fuzz_api fuzz_checkpoint fuzz_npy
api_seconds=$((seconds / 2))
checkpoint_seconds=$((seconds / 4))
npy_seconds=$((seconds - api_seconds - checkpoint_seconds))
mkdir -p "$build/corpus" "$build/corpus_checkpoint" "$build/corpus_npy"
cd "$build"
# -timeout: one input taking seconds is a hang worth reporting.
# -len_control=0: programs up to max_len from the start (libFuzzer's default
# grows the limit slowly: it stayed at 196 bytes, some 30 calls, for 8 minutes).
ASAN_OPTIONS=detect_leaks=1 "$build/tests/fuzz/fuzz_api" -max_total_time="$api_seconds" \
    -timeout=10 -rss_limit_mb=2048 -max_len=512 -len_control=0 -print_final_stats=1 \
    "$build/corpus" "$root/tests/fuzz/corpus"
# -max_len: a little over the largest seed (a sine-Euler N = 5 checkpoint).
ASAN_OPTIONS=detect_leaks=1 "$build/tests/fuzz/fuzz_checkpoint" \
    -max_total_time="$checkpoint_seconds" -timeout=10 -rss_limit_mb=2048 -max_len=1024 \
    -print_final_stats=1 "$build/corpus_checkpoint" "$root/tests/fuzz/corpus_checkpoint"
# -max_len: a little over the largest seed.
ASAN_OPTIONS=detect_leaks=1 "$build/tests/fuzz/fuzz_npy" -max_total_time="$npy_seconds" -timeout=10 \
    -rss_limit_mb=2048 -max_len=512 -print_final_stats=1 "$build/corpus_npy" "$root/tests/fuzz/corpus_npy"
