#!/bin/sh
# check_valgrind.sh BUILD JOBS HEADER [SKIP...]
# The cmocka tests of BUILD (and example_user_system) under valgrind's
# memcheck, JOBS at a time: no errors, no definite or indirect leaks. Each
# test's report goes to BUILD/valgrind/NAME.log and is printed when it fails.
# The tests named in SKIP are left out (see the Makefile's VALGRIND_SKIP). A
# test that exits 77 had nothing to run in this build (tests/lpi_test.h).
set -eu
build=$(cd "$1" && pwd)
jobs=$2
header=$3
shift 3
logs="$build/valgrind"

# One test (xargs's call): prints its verdict, and its report when it fails
# (exit 255 stops xargs).
if [ "${LPI_VALGRIND_ONE:-}" = 1 ]; then
    name=$(basename "$1")
    args=""
    [ "$name" = test_bad_input ] && args="$header"
    status=0
    start=$(date +%s)
    (cd "$build/tests" && CMOCKA_MESSAGE_OUTPUT=stdout valgrind -q --leak-check=full \
        --errors-for-leak-kinds=definite,indirect --error-exitcode=1 --log-file="$logs/$name.log" \
        "./$name" $args >/dev/null 2>&1) || status=$?
    case $status in
        0) echo "valgrind: $name ($(( $(date +%s) - start )) s)" ;;
        77) echo "valgrind: $name skipped itself (nothing to run in this build)" ;;
        *) echo "valgrind: $name FAILED (exit $status)"; cat "$logs/$name.log"; exit 255 ;;
    esac
    exit 0
fi

skip=" $* "
rm -rf "$logs"
mkdir -p "$logs"

for t in "$build"/tests/test_* "$build"/tests/example_user_system; do
    name=$(basename "$t")
    [ -x "$t" ] && [ -f "$t" ] || continue
    case "$skip" in *" $name "*) echo "valgrind: $name skipped" >&2; continue ;; esac
    echo "$t"
done >"$logs/tests"
LPI_VALGRIND_ONE=1 xargs -P "$jobs" -n 1 "$0" "$build" "$jobs" "$header" <"$logs/tests"
echo "valgrind: no errors, no leaks"
