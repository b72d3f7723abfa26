#!/bin/sh
# The threads test (tests/test_threads.c) in a host program built by the
# other compiler than the library, with the other OpenMP runtime:
#  - built by Clang (libomp) against the GCC build's library (libgomp), as a
#    host built with clang -fopenmp is: libomp, loaded first, also defines
#    GOMP_parallel and the omp_* calls, and takes the library's. The library
#    must then apply libomp's thread stacks and fork(2), not libgomp's
#    (src/core/threads.cpp): with libgomp's, libomp ended the process under a
#    low address-space limit. Fails unless the library's GOMP_parallel is in
#    fact bound to libomp, so that it cannot pass without testing that case.
#  - built by GCC (libgomp) against the Clang build's library (libomp): two
#    runtimes in one process, the host's regions on libgomp, the library's
#    on libomp.
# Usage: tests/check_mixed_openmp.sh GCC_BUILD CLANG_BUILD
set -eu
for build in "$1" "$2"; do
    grep -q 'LPI_HAVE_OPENMP 1' "$build/generated/lpi_config.h" ||
        { echo "check_mixed_openmp: $build has no OpenMP"; exit 1; }
done
gcc_build=$(cd "$1" && pwd)
clang_build=$(cd "$2" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# host_test COMPILER LIBRARY_BUILD: the test built by COMPILER, linked against
# LIBRARY_BUILD's library, at $work/host.
host_test() {
    "$1" -O1 -fopenmp -Iinclude -Itests tests/test_threads.c -o "$work/host" \
        -L"$2" -lliepoisson -lcmocka -lpthread -ldl -lm -Wl,-rpath,"$2"
}

host_test clang "$gcc_build"
LD_BIND_NOW=1 LD_DEBUG=bindings LD_DEBUG_OUTPUT="$work/bindings" "$work/host"
if ! cat "$work"/bindings.* | grep -q "libliepoisson.so.* to .*libomp.so.*GOMP_parallel"; then
    echo "check_mixed_openmp: the GCC-built library's GOMP_parallel is not bound to libomp:"
    cat "$work"/bindings.* | grep "GOMP_parallel" || echo "(no binding of GOMP_parallel)"
    exit 1
fi
echo "check_mixed_openmp: a Clang host (libomp) of the GCC-built library: test_threads passed"

host_test gcc "$clang_build"
"$work/host"
echo "check_mixed_openmp: a GCC host (libgomp) of the Clang-built library: test_threads passed"
