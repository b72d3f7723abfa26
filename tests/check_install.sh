#!/bin/sh
# Installs the build into a staging directory (DESTDIR) and builds and runs an
# outside C program against it: via pkg-config (shared and static) and via
# CMake's find_package (shared and static); a Fortran program too when the
# Fortran binding is built.
# Usage: check_install.sh BUILD PREFIX LIBDIR INCLUDEDIR CC CMAKE HAVE_FORTRAN [FC]
set -eu
build=$1 prefix=$2 libdir=$3 includedir=$4 cc=$5 cmake=$6 have_fortran=$7 fc=${8:-}
work=$(mktemp -d "${TMPDIR:-/tmp}/lpi-install.XXXXXX")
trap 'rm -rf "$work"' EXIT
stage=$work/stage
root=$stage$prefix
fail() { echo "check_install: $*"; exit 1; }

DESTDIR=$stage "$cmake" --install "$build" >"$work/install.log" 2>&1 || { cat "$work/install.log"; fail "install failed"; }

# What must be there.
for f in "$includedir/liepoisson.h" "$libdir/libliepoisson.a" "$libdir/pkgconfig/liepoisson.pc" \
         "$libdir/cmake/liepoisson/liepoissonConfig.cmake" "$libdir/cmake/liepoisson/liepoissonConfigVersion.cmake" \
         "bin/lpi" "share/man/man3/lpi_step.3" "share/man/man7/liepoisson.7"; do
    [ -e "$root/$f" ] || fail "missing $prefix/$f"
done
major=$(sed -n 's/^#define LPI_VERSION_MAJOR \([0-9]*\).*/\1/p' "$root/$includedir/liepoisson.h")
[ -L "$root/$libdir/libliepoisson.so" ] || fail "libliepoisson.so is not a link"
[ "$(readlink "$root/$libdir/libliepoisson.so")" = "libliepoisson.so.$major" ] || fail "libliepoisson.so does not point at the SONAME"
soname=$(readelf -d "$root/$libdir/libliepoisson.so.$major" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
[ "$soname" = "libliepoisson.so.$major" ] || fail "SONAME is '$soname'"
if [ "$have_fortran" = 1 ]; then
    [ -e "$root/$includedir/liepoisson.mod" ] || fail "missing the Fortran module"
    [ -e "$root/$libdir/libliepoisson_fortran.so.$major" ] || fail "missing libliepoisson_fortran"
fi
LD_LIBRARY_PATH=$root/$libdir "$root/bin/lpi" --help >/dev/null || fail "the installed lpi does not run"

# The outside program: needs the rigid body, the methods and (when built) FFTW.
cat >"$work/prog.c" <<'PROG'
#include <liepoisson.h>
#include <math.h>
#include <stdio.h>
int main(void) {
    lpi_system *sys = NULL, *se = NULL;
    const double m0[3] = {1.0, 0.5, -0.3};
    double c0, c1;
    if (lpi_rigid_body_create(&sys, 1, 2, 3) || lpi_set_method(sys, "triple-jump-4") ||
        lpi_set_state(sys, m0, 3) || lpi_casimirs(sys, &c0, 1) || lpi_step(sys, 0.01, 1000) ||
        lpi_casimirs(sys, &c1, 1)) {
        printf("failed: %s\n", lpi_last_error(sys));
        return 1;
    }
    int s = lpi_sine_euler_create(&se, 5);
    if (s == LPI_OK) s = lpi_step(se, 0.01, 2);
    if (s != LPI_OK && s != LPI_ERR_UNSUPPORTED) return 1;
    printf("liepoisson %s: Casimir drift %.1e, sine-Euler %s\n", lpi_version_string(),
           fabs(c1 - c0), lpi_status_name(s));
    lpi_destroy(se);
    lpi_destroy(sys);
    return fabs(c1 - c0) < 1e-13 ? 0 : 1;
}
PROG

needed() { readelf -d "$1" | grep -c "NEEDED.*libliepoisson" || true; }

# pkg-config: the staged tree is found through the sysroot.
export PKG_CONFIG_PATH="$root/$libdir/pkgconfig" PKG_CONFIG_SYSROOT_DIR="$stage"
# shellcheck disable=SC2046
"$cc" -o "$work/prog_pc" "$work/prog.c" $(pkg-config --cflags --libs liepoisson) -lm \
    -Wl,-rpath,"$root/$libdir" || fail "pkg-config shared build failed"
[ "$(needed "$work/prog_pc")" = 1 ] || fail "shared build does not use libliepoisson.so"
"$work/prog_pc" || fail "pkg-config shared program failed"
# static: the archive, and everything it needs from Libs.private / Requires.private
libs=$(pkg-config --static --libs liepoisson | sed 's/-lliepoisson\b//')
# shellcheck disable=SC2086
"$cc" -o "$work/prog_static" "$work/prog.c" $(pkg-config --cflags liepoisson) \
    "$root/$libdir/libliepoisson.a" $libs || fail "pkg-config static build failed: pkg-config gave: $libs"
[ "$(needed "$work/prog_static")" = 0 ] || fail "static build still needs libliepoisson.so"
"$work/prog_static" || fail "pkg-config static program failed"
unset PKG_CONFIG_PATH PKG_CONFIG_SYSROOT_DIR

# CMake: find_package(liepoisson) with the shared and the static target.
mkdir -p "$work/cmake"
cat >"$work/cmake/CMakeLists.txt" <<'CM'
cmake_minimum_required(VERSION 3.18)
project(outside C)
find_package(liepoisson 0.1 REQUIRED)
add_executable(prog_shared prog.c)
target_link_libraries(prog_shared PRIVATE liepoisson::liepoisson m)
add_executable(prog_static prog.c)
target_link_libraries(prog_static PRIVATE liepoisson::liepoisson_static m)
CM
cp "$work/prog.c" "$work/cmake/"
"$cmake" -S "$work/cmake" -B "$work/cmake/build" -DCMAKE_C_COMPILER="$cc" \
    -DCMAKE_PREFIX_PATH="$root" >"$work/cmake.log" 2>&1 || { cat "$work/cmake.log"; fail "find_package failed"; }
"$cmake" --build "$work/cmake/build" >>"$work/cmake.log" 2>&1 || { cat "$work/cmake.log"; fail "CMake build failed"; }
"$work/cmake/build/prog_shared" || fail "CMake shared program failed"
[ "$(needed "$work/cmake/build/prog_static")" = 0 ] || fail "CMake static build needs libliepoisson.so"
"$work/cmake/build/prog_static" || fail "CMake static program failed"

# Fortran: use liepoisson from the installed module.
if [ "$have_fortran" = 1 ] && [ -n "$fc" ]; then
    cat >"$work/prog.f90" <<'F90'
program outside
    use liepoisson
    use, intrinsic :: iso_c_binding
    type(c_ptr) :: sys
    real(c_double) :: c(1)
    call lpi_rigid_body_create(sys, 1.0_c_double, 2.0_c_double, 3.0_c_double)
    call lpi_set_state(sys, [1.0_c_double, 0.5_c_double, -0.3_c_double])
    call lpi_step(sys, 0.01_c_double, 100)
    call lpi_casimirs(sys, c)
    if (abs(c(1) - 1.34_c_double) > 1e-13_c_double) stop 1
    call lpi_destroy(sys)
end program
F90
    "$fc" -o "$work/prog_f" -I"$root/$includedir" "$work/prog.f90" -L"$root/$libdir" \
        -lliepoisson_fortran -lliepoisson -Wl,-rpath,"$root/$libdir" || fail "Fortran build failed"
    # libliepoisson_fortran finds libliepoisson through the loader path (RUNPATH is not inherited)
    LD_LIBRARY_PATH="$root/$libdir" "$work/prog_f" || fail "Fortran program failed"
fi
echo "install: staged under DESTDIR; pkg-config (shared, static), CMake (shared, static)$( [ "$have_fortran" = 1 ] && echo ', Fortran module') all build and run"
