#!/bin/sh
# lpi run writes one CSV row per output interval plus the initial one, stays
# quiet (no progress bar) when stderr is not a terminal, rejects bad options,
# and draws vorticity snapshots for sine-Euler when FFTW and gnuplot are there.
set -eu
lpi="$1"; out="$2"
rm -rf "$out"
"$lpi" run rigid-body --method yoshida-6 --dt 0.1 --steps 50 --every 10 --out "$out" 2>"$out.err"
rows=$(wc -l < "$out/rigid-body.csv")
[ "$rows" -eq 7 ] || { echo "expected 7 lines (header + 6 rows), got $rows"; exit 1; }
[ ! -s "$out.err" ] || { echo "unexpected output on a non-terminal stderr:"; cat "$out.err"; exit 1; }
if "$lpi" run rigid-body --method no-such-method --out "$out" 2>/dev/null; then
    echo "an unknown method was accepted"; exit 1
fi
if "$lpi" run rigid-body --inertia 1,-2,3 --out "$out" 2>/dev/null; then
    echo "a negative inertia was accepted"; exit 1
fi
if "$lpi" run sine-euler --N 9 --dt 0.05 --steps 20 --every 2 --snapshots 5 --out "$out" >/dev/null 2>&1; then
    if command -v gnuplot >/dev/null 2>&1; then
        n=$(ls "$out"/vorticity_*.png | wc -l)
        [ "$n" -eq 3 ] || { echo "expected 3 vorticity snapshots, got $n"; exit 1; }
    fi
fi
echo "lpi run: CSV rows, quiet off a terminal, bad options refused, snapshots drawn"
