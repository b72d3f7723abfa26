#!/bin/sh
# check_lpi_stress_fault.sh LPI SHIM: lpi stress fails a method that loses its
# Casimirs, also where the run does not stay bounded. SHIM (stress_fault.c,
# preloaded) doubles the state after every step: |m|^2 grows fourfold a step,
# so every run of the case is unbounded and its Casimir drift is of order 1.
set -u
lpi=$1 shim=$2
out=$(LD_PRELOAD=$shim ASAN_OPTIONS=${ASAN_OPTIONS:-}:verify_asan_link_order=0 \
      "$lpi" stress --quick "rigid-body middle axis")
status=$?
fail() { echo "FAIL: $*"; printf '%s\n' "$out" | head -40; exit 1; }
[ "$status" -eq 1 ] || fail "exit status $status with every state doubled a step, not 1"
# Every Poisson run is judged: leapfrog at each step size is unbounded and failed.
rows=$(printf '%s\n' "$out" | grep -c ' leapfrog .* LPI_OK  *no  .*!! Casimir drift')
[ "$rows" -eq 5 ] || fail "$rows unbounded leapfrog runs marked '!! Casimir drift', not 5"
# The same case without the fault passes.
"$lpi" stress --quick "rigid-body middle axis" > /dev/null || fail "the case fails without the fault"
echo "lpi stress failed every run of the doubled state ($rows leapfrog rows), and passes without it"
