# The front door. CMake is the one build description; every target here
# drives it, so the two can never disagree.
#   make            build            make check   build and run every test
#   make run        the demonstration report      make bench   the benchmarks
#   make install PREFIX=/usr/local [DESTDIR=...]  make clean
#   make abi-baseline   rewrite abi/ from this build (an intended ABI change)
BUILD      ?= build
BUILD_TYPE ?= Release
PREFIX     ?= /usr/local
JOBS       ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_ARGS ?=
VERSION    := $(shell sed -n 's/^\#define LPI_VERSION_\(MAJOR\|MINOR\|PATCH\) \([0-9]*\).*/\2/p' include/liepoisson.h | paste -sd.)

.PHONY: all build deps configure check run bench install clean version abi-baseline

all: build

deps:
	@scripts/install-deps

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DCMAKE_INSTALL_PREFIX=$(PREFIX) $(CMAKE_ARGS) >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

check: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

run: build
	@$(BUILD)/lpi report --out $(BUILD)/report

bench: build
	@cmake --build $(BUILD) -j $(JOBS) --target benchmarks
	@for b in $(BUILD)/tests/bench/bench_*; do [ -x "$$b" ] && "$$b"; done

install: build
	@DESTDIR="$(DESTDIR)" cmake --install $(BUILD) --prefix $(PREFIX)

abi-baseline: build
	@tests/check_abi.sh --update . $(BUILD)/libliepoisson.so

clean:
	@rm -rf $(BUILD)

version:
	@echo $(VERSION)
