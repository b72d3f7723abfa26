#!/bin/sh
# The Fortran binding in a program whose default integer is 8 bytes: the
# module and its test built with gfortran -fdefault-integer-8 (as such a
# program must build the module, with its own default kind), then run. Fails
# unless the test's checks of values beyond C's 32-bit int ran.
# Usage: tests/check_fortran_integer8.sh FORTRAN_COMPILER SOURCE_DIR SCRATCH_DIR LIBRARY [FLAGS]
# FLAGS: the sanitizer of a sanitized library's build ("" for none).
set -eu
fc=$1
src=$2
work=$3
lib=$4
flags=${5:-}
libdir=$(dirname "$lib")
rm -rf "$work"
mkdir -p "$work"
cd "$work"
# -fcheck=recursion as the module's own build (CMakeLists.txt); bounds too.
# shellcheck disable=SC2086 # FLAGS: words
"$fc" -fdefault-integer-8 -fcheck=recursion,bounds $flags -J "$work" \
    "$src/bindings/fortran/liepoisson.f90" "$src/bindings/fortran/tests/test_liepoisson.f90" \
    -o test_fortran_integer8 -L"$libdir" -lliepoisson -Wl,-rpath,"$libdir"
status=0
./test_fortran_integer8 >output 2>&1 || status=$?
cat output
[ $status -eq 0 ] || { echo "check_fortran_integer8: the test exited with $status"; exit 1; }
grep -q "^default integer: 64 bits" output ||
    { echo "check_fortran_integer8: the default integer is not 64 bits"; exit 1; }
