#!/bin/sh
# Installs the build into a staging directory (DESTDIR) and checks that what is
# installed works from there with no LD_LIBRARY_PATH: the installed lpi and the
# Fortran library find libliepoisson through their $ORIGIN-relative RUNPATH (the
# staging directory is a moved prefix; a build with CMAKE_SKIP_INSTALL_RPATH has
# none); outside C programs build and run via pkg-config (shared; static from
# the archive with `pkg-config --static` flags alone) and via find_package
# (shared, static); a Fortran program via liepoisson-fortran.pc and CMake.
# Usage: check_install.sh BUILD PREFIX LIBDIR INCLUDEDIR CC CMAKE HAVE_FORTRAN [FC]
set -eu
build=$1 prefix=$2 libdir=$3 includedir=$4 cc=$5 cmake=$6 have_fortran=$7 fc=${8:-}
source_dir=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/lpi-install.XXXXXX")
trap 'rm -rf "$work"' EXIT
stage=$work/stage
root=$stage$prefix
fail() { echo "check_install: $*"; exit 1; }
unset LD_LIBRARY_PATH

DESTDIR=$stage "$cmake" --install "$build" >"$work/install.log" 2>&1 || { cat "$work/install.log"; fail "install failed"; }

# What must be there.
for f in "$includedir/liepoisson.h" "$libdir/libliepoisson.a" "$libdir/pkgconfig/liepoisson.pc" \
         "$libdir/cmake/liepoisson/liepoissonConfig.cmake" "$libdir/cmake/liepoisson/liepoissonConfigVersion.cmake" \
         "bin/lpi" "share/man/man3/lpi_step.3" "share/man/man7/liepoisson.7"; do
    [ -e "$root/$f" ] || fail "missing $prefix/$f"
done
version=$(sed -n 's/^#define LPI_VERSION_\(MAJOR\|MINOR\|PATCH\) \([0-9]*\).*/\2/p' "$root/$includedir/liepoisson.h" | paste -sd.)
major=${version%%.*}
[ -L "$root/$libdir/libliepoisson.so" ] || fail "libliepoisson.so is not a link"
[ "$(readlink "$root/$libdir/libliepoisson.so")" = "libliepoisson.so.$major" ] || fail "libliepoisson.so does not point at the SONAME"
soname=$(readelf -d "$root/$libdir/libliepoisson.so.$major" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
[ "$soname" = "libliepoisson.so.$major" ] || fail "SONAME is '$soname'"
if [ "$have_fortran" = 1 ]; then
    for f in "$includedir/liepoisson.mod" "$libdir/libliepoisson_fortran.so.$major" "$libdir/pkgconfig/liepoisson-fortran.pc"; do
        [ -e "$root/$f" ] || fail "missing $prefix/$f"
    done
fi

# RUNPATHs: relative to the file itself, never the build tree; none where the
# build was told to skip them (a system prefix), and the loader is told instead.
if grep -qE '^CMAKE_SKIP_INSTALL_RPATH:BOOL=(ON|TRUE|YES|1)$' "$build/CMakeCache.txt"; then
    lpi_runpath='' fortran_runpath=''
    export LD_LIBRARY_PATH="$root/$libdir"
else
    lpi_runpath="\$ORIGIN/../$libdir" fortran_runpath="\$ORIGIN"
fi
runpath() { readelf -d "$1" | sed -n 's/.*(R\(UN\)\{0,1\}PATH).*\[\(.*\)\]/\2/p'; }
# where the loader finds libliepoisson for FILE, with no LD_LIBRARY_PATH
resolved() {  # resolved PROGRAM [LIBRARY]: the file PROGRAM loads LIBRARY (libliepoisson) from
    found=$(ldd "$1" | sed -n "s/^[[:space:]]*${2:-libliepoisson}.so.$major => \([^ ]*\).*/\1/p")
    [ -n "$found" ] && readlink -f "$found"
}
staged_lib=$(readlink -f "$root/$libdir/libliepoisson.so.$major")
[ "$(runpath "$root/bin/lpi")" = "$lpi_runpath" ] || fail "installed lpi has RUNPATH '$(runpath "$root/bin/lpi")'"
[ -z "$(runpath "$root/$libdir/libliepoisson.so.$major")" ] || fail "libliepoisson has a RUNPATH"
# A build with MPI links lpi to libliepoisson_mpi (which carries the whole API).
lpi_lib=libliepoisson
ldd "$root/bin/lpi" | grep -q "libliepoisson_mpi.so.$major" && lpi_lib=libliepoisson_mpi
[ "$(resolved "$root/bin/lpi" $lpi_lib)" = "$(readlink -f "$root/$libdir/$lpi_lib.so.$major")" ] ||
    fail "installed lpi loads $lpi_lib from '$(resolved "$root/bin/lpi" $lpi_lib)'"
[ "$("$root/bin/lpi" --version)" = "lpi (liepoisson) $version" ] || fail "the installed lpi does not run"
if [ "$have_fortran" = 1 ]; then
    [ "$(runpath "$root/$libdir/libliepoisson_fortran.so.$major")" = "$fortran_runpath" ] ||
        fail "libliepoisson_fortran has RUNPATH '$(runpath "$root/$libdir/libliepoisson_fortran.so.$major")'"
fi
# No installed description names this machine's build or source tree.
if grep -rlF -e "$build" -e "$source_dir" "$root/$libdir/pkgconfig" "$root/$libdir/cmake"; then
    fail "the files above name the build or source tree"
fi

# The outside program: needs the rigid body, the methods and (when built) FFTW.
cat >"$work/prog.c" <<'PROG'
#include <liepoisson.h>
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
    const double drift = c1 > c0 ? c1 - c0 : c0 - c1;
    printf("liepoisson %s: Casimir drift %.1e, sine-Euler %s\n", lpi_version_string(), drift,
           lpi_status_name(s));
    lpi_destroy(se);
    lpi_destroy(sys);
    return drift < 1e-13 ? 0 : 1;
}
PROG

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

needed() { readelf -d "$1" | grep -c "NEEDED.*libliepoisson" || true; }

# pkg-config: the staged tree is a moved prefix, and its .pc files are moved
# with it by their first line alone (prefix=), so every path of ours must
# follow from ${prefix}. A sysroot would not do: it moves every -L, also those
# into the system a build names outside the prefix (Clang's libomp).
pc_moved_to() {  # pc_moved_to ROOT: a directory of the .pc files under ROOT, with prefix=ROOT
    mkdir -p "$work/pc$1"
    for pc in "$1/$libdir"/pkgconfig/*.pc; do
        [ "$(sed -n 1p "$pc")" = "prefix=$prefix" ] || fail "$(basename "$pc") does not begin with prefix=$prefix" >&2
        sed "1s|.*|prefix=$1|" "$pc" >"$work/pc$1/$(basename "$pc")"
    done
    echo "$work/pc$1"
}
PKG_CONFIG_PATH=$(pc_moved_to "$root")
export PKG_CONFIG_PATH
# shellcheck disable=SC2046
"$cc" -o "$work/prog_pc" "$work/prog.c" $(pkg-config --cflags --libs liepoisson) \
    -Wl,-rpath,"$root/$libdir" || fail "pkg-config shared build failed"
[ "$(needed "$work/prog_pc")" = 1 ] || fail "shared build does not use libliepoisson.so"
"$work/prog_pc" || fail "pkg-config shared program failed"
# Static, as the README says: beside the shared library, name the archive and
# let --as-needed drop the -lliepoisson that follows.
# shellcheck disable=SC2046
"$cc" -o "$work/prog_archive" "$work/prog.c" $(pkg-config --cflags liepoisson) "$root/$libdir/libliepoisson.a" \
    -Wl,--as-needed $(pkg-config --static --libs liepoisson) >"$work/static.log" 2>&1 ||
    { cat "$work/static.log"; fail "static build beside the shared library failed"; }
[ "$(needed "$work/prog_archive")" = 0 ] || fail "static build beside the shared library needs libliepoisson.so"
"$work/prog_archive" >/dev/null || fail "static program (built beside the shared library) failed"
# Static where only the archive is installed: `pkg-config --static` alone must
# name every private dependency; without --static the link must fail, or the
# check above proves nothing about Libs.private and Requires.private.
cp -R "$stage" "$work/stage-static"
rm -f "$work/stage-static$prefix/$libdir"/libliepoisson.so*
PKG_CONFIG_PATH=$(pc_moved_to "$work/stage-static$prefix")
# shellcheck disable=SC2046
"$cc" -o "$work/prog_static" "$work/prog.c" $(pkg-config --static --cflags --libs liepoisson) >"$work/static.log" 2>&1 ||
    { cat "$work/static.log"; fail "pkg-config static build failed: pkg-config gave: $(pkg-config --static --libs liepoisson)"; }
[ "$(needed "$work/prog_static")" = 0 ] || fail "static build still needs libliepoisson.so"
"$work/prog_static" >/dev/null || fail "pkg-config static program failed"
# shellcheck disable=SC2046
if "$cc" -o "$work/prog_no_private" "$work/prog.c" $(pkg-config --cflags --libs liepoisson) >/dev/null 2>&1; then
    fail "the archive links without its private dependencies: the static check is void"
fi
unset PKG_CONFIG_PATH

# CMake: the installed static target's link needs are plain flags, with no -L
# into a directory the compiler searches anyway.
default_dirs=$("$cc" -print-search-dirs | sed -n 's/^libraries: =//p' | tr : '\n' |
               while read -r d; do [ -d "$d" ] && (cd "$d" && pwd -P); done)
static_links=$(sed -n '/liepoisson::liepoisson_static PROPERTIES/,/^)/s/.*INTERFACE_LINK_LIBRARIES "\(.*\)"/\1/p' \
               "$root/$libdir/cmake/liepoisson/liepoissonTargets.cmake")
case "$static_links" in *'$<'*) fail "the static target's link libraries keep a generator expression: $static_links";; esac
for flag in $(echo "$static_links" | tr ';' ' '); do
    case "$flag" in
        -L*) d=$(cd "${flag#-L}" 2>/dev/null && pwd -P) || fail "the static target links from a missing ${flag#-L}"
             if echo "$default_dirs" | grep -qxF "$d"; then fail "the static target carries a needless $flag"; fi;;
    esac
done

# CMake: find_package(liepoisson) with the shared, the static and the Fortran target.
mkdir -p "$work/cmake"
cat >"$work/cmake/CMakeLists.txt" <<'CM'
cmake_minimum_required(VERSION 3.18)
project(outside C)
find_package(liepoisson 0.1 REQUIRED)
add_executable(prog_shared prog.c)
target_link_libraries(prog_shared PRIVATE liepoisson::liepoisson)
add_executable(prog_static prog.c)
target_link_libraries(prog_static PRIVATE liepoisson::liepoisson_static)
if(WITH_FORTRAN)
  enable_language(Fortran)
  add_executable(prog_f prog.f90)
  target_link_libraries(prog_f PRIVATE liepoisson::liepoisson_fortran)
endif()
# The MPI target as shipped: the package finds the MPI it links.
if(TARGET liepoisson::liepoisson_mpi)
  add_executable(prog_mpi prog_mpi.c)
  target_link_libraries(prog_mpi PRIVATE liepoisson::liepoisson_mpi)
endif()
CM
cat >"$work/cmake/prog_mpi.c" <<'C'
#include <liepoisson_mpi.h>
int main(int argc, char **argv) {
    (void)argv;
    lpi_system *sys = 0;
    return argc > 1 ? lpi_sine_euler_create_mpi(&sys, 5, MPI_COMM_WORLD) : 0;
}
C
cp "$work/prog.c" "$work/prog.f90" "$work/cmake/"
with_fortran=OFF
[ "$have_fortran" = 1 ] && [ -n "$fc" ] && with_fortran=ON
"$cmake" -S "$work/cmake" -B "$work/cmake/build" -DCMAKE_C_COMPILER="$cc" -DCMAKE_Fortran_COMPILER="$fc" \
    -DWITH_FORTRAN=$with_fortran -DCMAKE_PREFIX_PATH="$root" >"$work/cmake.log" 2>&1 ||
    { cat "$work/cmake.log"; fail "find_package failed"; }
"$cmake" --build "$work/cmake/build" >>"$work/cmake.log" 2>&1 || { cat "$work/cmake.log"; fail "CMake build failed"; }
"$work/cmake/build/prog_shared" >/dev/null || fail "CMake shared program failed"
[ "$(needed "$work/cmake/build/prog_static")" = 0 ] || fail "CMake static build needs libliepoisson.so"
"$work/cmake/build/prog_static" >/dev/null || fail "CMake static program failed"
if [ $with_fortran = ON ]; then "$work/cmake/build/prog_f" || fail "CMake Fortran program failed"; fi

# Fortran: the installed module through liepoisson-fortran.pc. The program's
# RUNPATH reaches libliepoisson_fortran only; libliepoisson is found through
# the Fortran library's own.
if [ "$have_fortran" = 1 ] && [ -n "$fc" ]; then
    PKG_CONFIG_PATH=$(pc_moved_to "$root")
    export PKG_CONFIG_PATH
    # shellcheck disable=SC2046
    "$fc" -o "$work/prog_f" "$work/prog.f90" $(pkg-config --cflags --libs liepoisson-fortran) \
        -Wl,-rpath,"$root/$libdir" || fail "Fortran build through liepoisson-fortran.pc failed"
    unset PKG_CONFIG_PATH
    [ "$(resolved "$work/prog_f")" = "$staged_lib" ] ||
        fail "the Fortran program loads libliepoisson from '$(resolved "$work/prog_f")'"
    "$work/prog_f" || fail "Fortran program failed"
fi
# `cmake --install --prefix` after configuring: the .pc files name that
# prefix (written when installed); a relative prefix is refused before
# anything is installed.
"$cmake" --install "$build" --prefix "$work/elsewhere" >"$work/install2.log" 2>&1 ||
    { cat "$work/install2.log"; fail "install --prefix failed"; }
for pc in "$work/elsewhere/$libdir"/pkgconfig/*.pc; do
    [ "$(sed -n 1p "$pc")" = "prefix=$work/elsewhere" ] ||
        fail "$(basename "$pc") after install --prefix: $(sed -n 1p "$pc")"
done
if (cd "$work" && "$cmake" --install "$build" --prefix relative >"$work/install3.log" 2>&1); then
    fail "a relative install prefix was taken"
fi
grep -q "is not an absolute path" "$work/install3.log" || { cat "$work/install3.log"; fail "no message for a relative prefix"; }
[ ! -e "$work/relative" ] || fail "a relative install prefix left $(cd "$work" && find relative | head -3)"
echo "install: staged under DESTDIR, run without LD_LIBRARY_PATH: lpi, pkg-config (shared, static)," \
     "CMake (shared, static, MPI where built)$( [ "$have_fortran" = 1 ] && echo ', Fortran via liepoisson-fortran.pc and CMake') all build and run;" \
     "install --prefix names its prefix in the .pc files; a relative prefix is refused"
