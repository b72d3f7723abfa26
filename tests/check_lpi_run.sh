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

# --checkpoint / --resume: 20 steps, then 30 more from the checkpoint, end
# exactly (to the bit) where 50 steps in one run end.
"$lpi" run pendulum --method suzuki-4 --dt 0.05 --steps 50 --every 10 --out "$out/whole" >/dev/null
"$lpi" run pendulum --method suzuki-4 --dt 0.05 --steps 20 --every 10 --out "$out/parts" \
    --checkpoint "$out/pendulum.lpi" >/dev/null
"$lpi" run pendulum --dt 0.05 --steps 30 --every 10 --out "$out/parts" --resume "$out/pendulum.lpi" >/dev/null
whole=$(tail -1 "$out/whole/pendulum.csv" | cut -d, -f1-3,5-)
parts=$(tail -1 "$out/parts/pendulum.csv" | cut -d, -f1-3,5-)
[ "$whole" = "$parts" ] || { echo "resumed run differs: '$whole' vs '$parts'"; exit 1; }
[ "$(wc -l < "$out/parts/pendulum.csv")" -eq 7 ] || { echo "resumed rows not appended"; exit 1; }
if "$lpi" run pendulum --resume "$out/no-such-file.lpi" --out "$out" 2>/dev/null; then
    echo "a missing checkpoint was accepted"; exit 1
fi
echo "lpi run: --checkpoint then --resume continues to the bit"
