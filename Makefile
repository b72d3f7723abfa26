# The front door. CMake is the one build description; every target here
# drives it, so the two can never disagree.
#   make            build            make check   build and run every test
#   make run        the demonstration report      make bench   the benchmarks
#   make install PREFIX=/usr/local [DESTDIR=...]  make clean
#   make abi-baseline   rewrite abi/ from this build (an intended ABI change)
#   make check-asan      every test under AddressSanitizer + UBSan (build-asan)
#   make check-tsan      the threads test under ThreadSanitizer (build-tsan)
#   make check-clang     the threads test built by Clang with libomp (build-clang),
#                        and in hosts of the other compiler and runtime than
#                        the library's (tests/check_mixed_openmp.sh)
#   make check-valgrind  the cmocka tests under valgrind, no leaks allowed
#   make check-build-alone  with cmocka hidden: -DBUILD_TESTING=OFF builds the
#                        library, lpi and the bindings (build-alone)
#   make fuzz FUZZ_SECONDS=60  the libFuzzer harnesses from their corpora (clang)
# Quiet by default: only the compilers' warnings and errors (and CMake's). V=1
# shows CMake's status lines, the progress lines and every command.
BUILD      ?= build
BUILD_TYPE ?= Release
PREFIX     ?= /usr/local
JOBS       ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_ARGS ?=
V          ?= 0
VERSION    := $(shell sed -n 's/^\#define LPI_VERSION_\(MAJOR\|MINOR\|PATCH\) \([0-9]*\).*/\2/p' include/liepoisson.h | paste -sd.)

ifeq ($(V),0)
  STATUS_OUT    := >/dev/null
  OUTPUT_ARGS   := -DCMAKE_RULE_MESSAGES=OFF -DCMAKE_TARGET_MESSAGES=OFF
  BUILD_ARGS    :=
  MAKEFLAGS     += --no-print-directory
else
  STATUS_OUT    :=
  OUTPUT_ARGS   := -DCMAKE_RULE_MESSAGES=ON -DCMAKE_TARGET_MESSAGES=ON
  BUILD_ARGS    := --verbose
endif

.PHONY: all build deps configure check run bench bench-quick install clean version abi-baseline \
        check-asan check-tsan check-clang check-valgrind check-build-alone fuzz

all: build

deps:
	@scripts/install-deps

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DCMAKE_INSTALL_PREFIX=$(abspath $(PREFIX)) $(OUTPUT_ARGS) $(CMAKE_ARGS) $(STATUS_OUT)

build: configure
	@cmake --build $(BUILD) -j $(JOBS) $(BUILD_ARGS)

check: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

run: build
	@$(BUILD)/lpi report --out $(BUILD)/report

bench: build
	@cmake --build $(BUILD) -j $(JOBS) $(BUILD_ARGS) --target benchmarks
	@for b in $(BUILD)/tests/bench/bench_*; do [ -x "$$b" ] || continue; case "$$b" in \
	    *_mpi) OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe -np 4 "$$b";; \
	    *) "$$b";; esac || exit 1; done

# Every benchmark on its smallest sizes and shortest runs (LPI_BENCH_QUICK,
# tests/bench/bench_common.h): that `make bench` runs to the end. CI runs it;
# the figures it prints mean nothing.
bench-quick:
	@LPI_BENCH_QUICK=1 $(MAKE) --no-print-directory bench

# Quiet, but says where the Python package went (and whether python3 finds it).
install: build
	@DESTDIR="$(DESTDIR)" cmake --install $(BUILD) --prefix $(abspath $(PREFIX)) >$(BUILD)/install.log || \
	    { cat $(BUILD)/install.log; exit 1; }
	@if [ "$(V)" = 0 ]; then sed -n 's/^-- liepoisson: //p' $(BUILD)/install.log; else cat $(BUILD)/install.log; fi
	@echo "liepoisson $(VERSION) installed in $(DESTDIR)$(abspath $(PREFIX))"

abi-baseline: build
	@tests/check_abi.sh --update . $(BUILD)/libliepoisson.so

clean:
	@rm -rf $(BUILD)

# Sanitized builds live in their own directories. RelWithDebInfo keeps the
# suite's run time reasonable while reports still carry lines. The tests that
# load the library into an uninstrumented host (the Python interpreter, a
# gfortran program, outside programs built against an install, the Python
# and Fortran examples) cannot run with the ASan runtime and are left out
# here; they run in `make check`.
ASAN_EXCLUDE = ^test_python_|^test_fortran$$|^test_install$$|^example_python$$|^example_fortran$$
check-asan: deps
	@cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLPI_SANITIZE=ON $(OUTPUT_ARGS) $(CMAKE_ARGS) $(STATUS_OUT)
	@cmake --build build-asan -j $(JOBS) $(BUILD_ARGS)
	@cd build-asan && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
	    ctest --output-on-failure -j $(JOBS) -E '$(ASAN_EXCLUDE)'

# OpenMP is left out: libgomp is not instrumented and would give false reports.
check-tsan: deps
	@cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLPI_TSAN=ON -DLPI_WITH_OPENMP=OFF $(OUTPUT_ARGS) $(CMAKE_ARGS) $(STATUS_OUT)
	@cmake --build build-tsan -j $(JOBS) $(BUILD_ARGS) --target test_threads
	@cd build-tsan && TSAN_OPTIONS=halt_on_error=1 ctest --output-on-failure -R '^test_threads$$'

# Clang with LLVM's OpenMP runtime, libomp, where the library's guards of the
# runtime (src/core/threads.cpp: the thread probe, fork) differ from libgomp's:
# the threads test (build-clang), then in hosts built by the other compiler,
# each with its own runtime (tests/check_mixed_openmp.sh: a Clang host's
# libomp takes the GCC build's OpenMP calls). Needs clang and libomp-dev
# (scripts/install-deps --ci).
check-clang: build
	@cmake -S . -B build-clang -DCMAKE_BUILD_TYPE=Release -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ $(OUTPUT_ARGS) $(CMAKE_ARGS) $(STATUS_OUT)
	@grep -q 'LPI_HAVE_OPENMP 1' build-clang/generated/lpi_config.h || \
	    { echo "check-clang: clang found no OpenMP runtime (apt-get install libomp-dev)"; exit 1; }
	@cmake --build build-clang -j $(JOBS) $(BUILD_ARGS) --target test_threads
	@cd build-clang && ctest --output-on-failure -R '^test_threads$$'
	@tests/check_mixed_openmp.sh $(BUILD) build-clang >build-clang/check_mixed_openmp.log 2>&1 || \
	    { cat build-clang/check_mixed_openmp.log; exit 1; }
	@grep '^check_mixed_openmp' build-clang/check_mixed_openmp.log

# The cmocka tests of $(BUILD) under valgrind, $(JOBS) at a time
# (tests/check_valgrind.sh). VALGRIND_SKIP leaves out the
# two slowest (minutes each under valgrind) and test_expm, whose long double
# references need x87 80-bit arithmetic that valgrind performs in 64 bits
# (its assertions then fail), and the MPI tests (test_sine_euler_mpi,
# test_sine_euler_mpi_observer and test_sine_euler_mpi_allocations), which run
# under mpirun (valgrind reports Open MPI's own allocations and its
# shared-memory transport).
# `make check-valgrind VALGRIND_SKIP=` runs all.
VALGRIND_SKIP ?= test_compositions test_sine_euler test_expm test_sine_euler_mpi test_sine_euler_mpi_observer \
                 test_sine_euler_mpi_allocations
check-valgrind: build
	@tests/check_valgrind.sh $(BUILD) $(JOBS) $(CURDIR)/include/liepoisson.h $(VALGRIND_SKIP)

# Not in BUILD: a build of its own, configured with cmocka hidden.
check-build-alone: deps
	@JOBS=$(JOBS) tests/check_build_alone.sh build-alone $(CMAKE_ARGS)

FUZZ_SECONDS ?= 60
fuzz:
	@tests/fuzz/run.sh $(FUZZ_SECONDS)

version:
	@echo $(VERSION)
