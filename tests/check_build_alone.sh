#!/bin/sh
# check_build_alone.sh DIR [CMAKE_ARG...]
# The library builds alone: with cmocka hidden from pkg-config, a plain
# configure stops with a message naming libcmocka-dev and -DBUILD_TESTING=OFF,
# and -DBUILD_TESTING=OFF configures and builds the libraries, lpi and the
# Fortran binding (when a Fortran compiler is found) and no test.
set -eu
dir=$1
shift
fail() { echo "check_build_alone: $*"; exit 1; }
rm -rf "$dir"
mkdir -p "$dir/pkgconfig"
# pkg-config sees every module of this machine but cmocka.
for d in $(pkg-config --variable pc_path pkg-config | tr : ' '); do
    for pc in "$d"/*.pc; do
        [ -e "$pc" ] && ln -sf "$pc" "$dir/pkgconfig/"
    done
done
rm -f "$dir/pkgconfig/cmocka.pc"
export PKG_CONFIG_LIBDIR="$dir/pkgconfig"
unset PKG_CONFIG_PATH
! pkg-config --exists cmocka || fail "cmocka still visible to pkg-config"

if cmake -S . -B "$dir/with-tests" "$@" >"$dir/with-tests.log" 2>&1; then
    fail "configured with the tests but without cmocka"
fi
grep -q "libcmocka-dev" "$dir/with-tests.log" && grep -q -- "-DBUILD_TESTING=OFF" "$dir/with-tests.log" ||
    { cat "$dir/with-tests.log"; fail "the configure without cmocka does not say what to install or how to turn tests off"; }

build=$dir/alone
cmake -S . -B "$build" -DBUILD_TESTING=OFF "$@" >"$dir/alone.log" 2>&1 || { cat "$dir/alone.log"; fail "configure failed"; }
cmake --build "$build" -j "${JOBS:-2}" >"$dir/build.log" 2>&1 || { cat "$dir/build.log"; fail "build failed"; }
for f in lpi libliepoisson.so libliepoisson.a; do
    [ -e "$build/$f" ] || fail "no $f"
done
if grep -q '^CMAKE_Fortran_COMPILER:[A-Z]*=/' "$build/CMakeCache.txt"; then
    for f in libliepoisson_fortran.so fortran/liepoisson.mod; do
        [ -e "$build/$f" ] || fail "a Fortran compiler was found but no $f was built"
    done
    fortran=", the Fortran binding"
else
    fortran=" (no Fortran compiler: no Fortran binding)"
fi
[ ! -e "$build/tests" ] || fail "-DBUILD_TESTING=OFF still built tests"
"$build/lpi" run rigid-body --steps 10 --out "$build/run" >/dev/null || fail "the lpi built alone does not run"
echo "check_build_alone: without cmocka the libraries, lpi$fortran build with -DBUILD_TESTING=OFF"
