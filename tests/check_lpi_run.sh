#!/bin/sh
# lpi run writes one CSV row per output interval plus the initial one, stays
# quiet (no progress bar) when stderr is not a terminal, refuses every bad
# option with exit status 2 and a message, fails (non-zero) when it cannot
# write, stops on SIGINT with a complete last row and checkpoint (exit 130),
# and a run interrupted and resumed ends bit for bit where the uninterrupted
# run ends, whatever --every is.
set -eu
lpi="$1"; out="$2"
rm -rf "$out"
mkdir -p "$out"
"$lpi" run rigid-body --method yoshida-6 --dt 0.1 --steps 50 --every 10 --out "$out" 2>"$out.err" >/dev/null
rows=$(wc -l < "$out/rigid-body.csv")
[ "$rows" -eq 7 ] || { echo "expected 7 lines (header + 6 rows), got $rows"; exit 1; }
[ ! -s "$out.err" ] || { echo "unexpected output on a non-terminal stderr:"; cat "$out.err"; exit 1; }

# Every bad option: exit status 2 and a message naming the option.
refused() {  # refused OPTION-NAME-IN-MESSAGE lpi-arguments...
    what="$1"; shift
    rc=0
    "$lpi" "$@" >/dev/null 2>"$out.err" || rc=$?
    [ "$rc" -eq 2 ] || { echo "lpi $*: exit status $rc, expected 2"; cat "$out.err"; exit 1; }
    grep -q -e "$what" "$out.err" || { echo "lpi $*: no message naming $what:"; cat "$out.err"; exit 1; }
}
rb="run rigid-body --out $out/bad"
for v in -5 0 -0 nan inf 1e400 1e-400 "" 10x " 5" 0x; do refused --until $rb --until "$v"; done
for v in 0 -0 -1 nan -inf 1e999 "" 1e-320 0.1.2; do refused --dt $rb --dt "$v"; done
for v in -3 0 2.9 1e400 "" 10x 9223372036854775808 18446744073709551621 nan 4611686018427387904; do refused --steps $rb --steps "$v"; done
for v in 0 -1 0.5 9223372036854775808 ""; do refused --every $rb --every "$v"; done
for v in 0 -1 4294967297 2147483648 1.5; do refused --threads $rb --threads "$v"; done
for v in 1e12 4 1 -7 2.5 4294967303 ""; do refused --N run sine-euler --out "$out/bad" --N "$v"; done
for v in -1 1.5 x; do refused --snapshots $rb --snapshots "$v"; done
for v in -1 1.5; do refused --checkpoint-every $rb --checkpoint-every "$v"; done
for v in 1,-2,3 1,2 1,2,3,4 1,,3 1,nan,3 a,b,c ""; do refused --inertia $rb --inertia "$v"; done
refused --dt $rb --dt 0.1 --dt 0.2
refused --steps $rb --steps 5 --until 3
refused --dt $rb --dt
refused --method $rb --method no-such-method
refused --method $rb --method ""
refused --out $rb --out ""
refused --checkpoint $rb --checkpoint ""
refused --resume $rb --resume ""
refused --bogus $rb --bogus 1
refused "one scene" run rigid-body pendulum
refused "which scene" run
refused no-such-scene run no-such-scene
refused "less than one step" $rb --until 0.001 --dt 0.01
refused "too many steps" $rb --until 1e300 --dt 1e-300
refused --N report --N 1e12 --out "$out/bad"
refused --N report --N 8 --out "$out/bad"
refused --out report --out
refused no-such-scene report no-such-scene
refused "named twice" report pendulum rigid-body pendulum --out "$out/bad"
refused --bogus report --bogus
refused FILTER stress a b
# An option may be given once, a flag too; an operand is never empty; an
# argument after a command's --help is refused, not ignored.
refused --quick stress --quick --quick "pendulum near"
refused "empty argument" stress "" "pendulum near"
refused "empty argument" run "" rigid-body --steps 2 --out "$out/bad"
refused "empty argument" report "" --out "$out/bad"
for command in run report stress methods; do refused --bogus $command --help --bogus; done
refused no-such-case stress no-such-case
refused --bogus stress --bogus
refused argument methods extra
refused no-such-command no-such-command
# Numbers are decimal: strtod's hexadecimal is refused.
refused --steps $rb --steps 0x10
refused --dt $rb --dt 0x1p-3 --steps 2
# An option that would be ignored is refused, naming it: one that configures
# other scenes, anything but --N, --steps, --dt and --out for rollup, and a
# report option no reported scene takes.
refused --kd $rb --kd 3
refused --N $rb --N 5
refused --inertia run sine-euler --N 5 --inertia 1,2,3 --out "$out/bad"
refused --wisdom run pendulum --wisdom "$out/w" --out "$out/bad"
refused --N run figure2 --N 5 --out "$out/bad"
for option in "--every 3" "--threads 2" "--planning patient" "--snapshots 2" "--format npy" "--kd 2"; do
    refused "${option% *}" run rollup --N 5 --steps 3 $option --out "$out/bad"
done
refused --N report rigid-body --N 5 --out "$out/bad"
refused --checkpoint-every $rb --checkpoint-every 5
# Rows or snapshots past 2^28 values, which lpi keeps in memory and reads back
# no larger, are refused before the run.
refused --every $rb --steps 1000000000 --every 1 --snapshots 0
refused --snapshots $rb --steps 200000000 --every 1 --snapshots 1
refused --checkpoint-every $rb --checkpoint-every 0 --resume "$out/none.ckpt"
refused --T report pendulum --T 5 --out "$out/bad"

# Every failure: non-zero. A checkpoint that cannot be written stops the run
# before any step (it used to fail every save and still exit 0).
rc=0; "$lpi" run rigid-body --steps 5 --checkpoint "$out/no-such-dir/x.lpi" --out "$out/f" >/dev/null 2>&1 || rc=$?
[ "$rc" -eq 1 ] || { echo "a checkpoint into a missing directory: exit status $rc"; exit 1; }
# The output folder it made for the run goes again (it was left empty).
[ ! -e "$out/f" ] || { echo "a refused checkpoint left the new --out folder $out/f"; exit 1; }
rc=0; "$lpi" run rigid-body --steps 5 --out "$out/no-such-dir/deeper" >/dev/null 2>&1 || rc=$?
[ "$rc" -eq 1 ] || { echo "an output directory that cannot be made: exit status $rc"; exit 1; }
rc=0; "$lpi" run pendulum --resume "$out/no-such-file.lpi" --out "$out/f" >/dev/null 2>&1 || rc=$?
[ "$rc" -eq 1 ] || { echo "a missing checkpoint: exit status $rc"; exit 1; }
rc=0; "$lpi" run rigid-body --dt 1e308 --steps 3 --out "$out/f" >/dev/null 2>&1 || rc=$?
[ "$rc" -eq 1 ] || { echo "a step that overflows: exit status $rc"; exit 1; }
# Output that cannot be written: exit status 1 and a message, never 0. An
# --out that is a regular file fails at once, before the work.
failed() {  # failed MESSAGE-PART lpi-arguments... (stdout to /dev/full when FULL=1)
    what="$1"; shift
    rc=0
    stdout=/dev/null; [ "${FULL:-0}" = 1 ] && stdout=/dev/full
    # A hang (lpi reading a FIFO) ends after a minute as a failure.
    timeout 60 "$lpi" "$@" >$stdout 2>"$out.err" || rc=$?
    [ "$rc" -eq 1 ] || { echo "lpi $*: exit status $rc, expected 1"; cat "$out.err"; exit 1; }
    grep -q -e "$what" "$out.err" || { echo "lpi $*: no message with '$what':"; cat "$out.err"; exit 1; }
}
: > "$out/a-file"
failed "not a directory" run pendulum --steps 3 --out "$out/a-file"
failed "not a directory" report pendulum --out "$out/a-file"
if [ -w /dev/full ]; then
    FULL=1 failed "standard output" run rigid-body --steps 100 --out "$out/f"
    FULL=1 failed "standard output" stress --quick "pendulum near"
    FULL=1 failed "standard output" methods
fi
# Sine-Euler runs where the build has it (FFTW); otherwise lpi says so. The
# parts left out are named.
rc=0
"$lpi" run sine-euler --N 9 --dt 0.05 --steps 20 --every 2 --snapshots 5 --out "$out" >/dev/null 2>"$out.err" || rc=$?
if [ "$rc" -eq 0 ]; then
    have_sine_euler=1
    if command -v gnuplot >/dev/null 2>&1; then
        n=$(ls "$out"/sine-euler_vorticity_*.png | wc -l)
        [ "$n" -eq 3 ] || { echo "expected 3 vorticity snapshots, got $n"; exit 1; }
    else
        echo "not checked: the vorticity snapshots (no gnuplot)"
    fi
    # Two scenes run into one --out each keep their own images and script
    # (SCENE_vorticity_STEP.png and .svg, SCENE_vorticity.gp), byte for byte
    # as each wrote them (unprefixed, the second drew over the first's at the
    # steps both have and left the first's others beside its own). A run
    # removes only its own stale images: not another scene's, nor the
    # unprefixed vorticity_STEP images and vorticity.gp of earlier versions.
    rm -rf "$out/shared"; mkdir -p "$out/shared"
    old="vorticity_000000.png vorticity_000004.svg vorticity.gp"
    for f in $old; do echo "an earlier version's" > "$out/shared/$f"; done
    (cd "$out/shared" && md5sum $old > "$out/old.md5")
    # own SCENE: the names of the scene's script and images in --out; drawn
    # SCENE K: they are its script and, with gnuplot, a PNG and an SVG of
    # each of its K snapshots; kept: the files of the MD5-FILE, and no other.
    own() {
        (cd "$out/shared" && for f in "$1"_vorticity.gp "$1"_vorticity_*; do if [ -e "$f" ]; then echo "$f"; fi; done)
    }
    drawn() {  # drawn SCENE SNAPSHOTS
        want=1; command -v gnuplot >/dev/null 2>&1 && want=$((1 + 2 * $2))
        n=$(own "$1" | wc -l)
        [ "$n" -eq "$want" ] ||
            { echo "$1 in a shared --out: $n files of its snapshots, expected $want:"; ls "$out/shared"; exit 1; }
    }
    kept() {  # kept SCENE MD5-FILE WHAT
        (cd "$out/shared" && md5sum -c --quiet "$2") && [ "$(own "$1" | wc -l)" -eq "$(wc -l < "$2")" ] ||
            { echo "$3 changed $1's images or script: $(ls "$out/shared")"; exit 1; }
    }
    "$lpi" run sine-euler --N 5 --steps 10 --every 1 --snapshots 3 --checkpoint "$out/shared-se.lpi" \
        --out "$out/shared" >/dev/null
    drawn sine-euler 4
    (cd "$out/shared" && own sine-euler | xargs md5sum > "$out/se.md5")
    "$lpi" run sqg --N 5 --steps 6 --every 1 --snapshots 2 --out "$out/shared" >/dev/null
    drawn sqg 4
    kept sine-euler "$out/se.md5" "an sqg run into the same --out"
    (cd "$out/shared" && own sqg | xargs md5sum > "$out/sqg.md5")
    # sine-euler resumed (extended to step 16): sqg's files are untouched.
    "$lpi" run sine-euler --N 5 --steps 16 --resume "$out/shared-se.lpi" --out "$out/shared" >/dev/null
    drawn sine-euler 6
    kept sqg "$out/sqg.md5" "a resumed sine-euler run into the same --out"
    (cd "$out/shared" && own sine-euler | xargs md5sum > "$out/se.md5")
    # sqg again with other snapshots removes its own stale images (steps 2
    # and 4), and only those.
    "$lpi" run sqg --N 5 --steps 6 --every 1 --snapshots 3 --out "$out/shared" >/dev/null
    drawn sqg 3
    ! own sqg | grep -q -e "_00000[24]\." || { echo "sqg's stale images left: $(ls "$out/shared")"; exit 1; }
    kept sine-euler "$out/se.md5" "an sqg run with other snapshots into the same --out"
    (cd "$out/shared" && md5sum -c --quiet "$out/old.md5") ||
        { echo "lpi run changed an earlier version's vorticity images or script: $(ls "$out/shared")"; exit 1; }
    # --checkpoint may not be a name of the scene's snapshot images in --out.
    refused "snapshot images" run sine-euler --N 5 --steps 2 --out "$out/shared" \
        --checkpoint "$out/shared/sine-euler_vorticity_000002.svg"
elif grep -q "sine-euler is not available in this build" "$out.err"; then
    have_sine_euler=0
    echo "not checked: sine-Euler runs and checkpoints (no FFTW in this build)"
else
    echo "lpi run sine-euler: exit status $rc"; cat "$out.err"; exit 1
fi
# rollup writes its own files (it needs sine-Euler to get that far).
[ "$have_sine_euler" = 0 ] || failed "not a directory" run rollup --N 5 --steps 3 --out "$out/a-file"
# A size too large for memory: the library refuses it (exit status 1, its
# message), never an abort from an allocation of lpi's own (where the build
# has sine-Euler: without it, lpi report skips the scene).
if [ "$have_sine_euler" = 1 ]; then
    for args in "run sine-euler --N 2147483647 --steps 1" "run sine-euler --N 99999 --steps 1" \
        "run qg --N 2147483647 --steps 1" "run topography --N 99999 --steps 1" \
        "run rollup --N 99999 --steps 1" "report sine-euler --N 99999"; do
        rc=0; "$lpi" $args --out "$out/huge" >/dev/null 2>"$out.err" || rc=$?
        [ "$rc" -eq 1 ] && ! grep -q "terminate called" "$out.err" ||
            { echo "lpi $args: exit status $rc, expected 1"; cat "$out.err"; exit 1; }
    done
fi

# --resume refuses a checkpoint of another scene, N, Hamiltonian or method.
"$lpi" run pendulum --dt 0.05 --steps 20 --out "$out/p" --checkpoint "$out/pendulum.lpi" >/dev/null
refused "not a checkpoint of this scene" run rigid-body --resume "$out/pendulum.lpi" --out "$out/bad"
"$lpi" run rigid-body --dt 0.05 --steps 20 --out "$out/r" --checkpoint "$out/rigid.lpi" >/dev/null
refused "Hamiltonian differs" run rigid-body --inertia 1,1,2 --resume "$out/rigid.lpi" --out "$out/bad"
# ... also where the energies agree at the checkpoint's state: I1 = 1.5 and
# the I2 that gives m1^2/I1 + m2^2/I2 its value for I = (1, 2, 3) at the state
# m the run ended at (its last snapshot, printed to 17 digits).
"$lpi" run rigid-body --dt 0.05 --steps 20 --every 10 --snapshots 1 --format npy --out "$out/m" \
    --checkpoint "$out/m.lpi" >/dev/null
same_energy=$(tail -c 24 "$out/m/rigid-body/state.npy" | od -An -t f8 -v --endian=little |
    awk '{ for (i = 1; i <= NF; ++i) m[++n] = $i }
         END { a = m[1] * m[1]; b = m[2] * m[2]; printf "1.5,%.17g,3", b / (a + b / 2 - a / 1.5) }')
refused "Hamiltonian differs" run rigid-body --inertia "$same_energy" --resume "$out/m.lpi" --out "$out/bad"
refused "not a whole number of steps" run rigid-body --dt 0.03 --resume "$out/rigid.lpi" --out "$out/bad"
refused "past the run's end" run rigid-body --dt 0.05 --steps 10 --resume "$out/rigid.lpi" --out "$out/bad"
# The checkpoint holds the run's method: another --method would splice rows
# of two methods (the checkpoint's own, by name or alias, resumes).
refused "--method rk4.*leapfrog" run rigid-body --dt 0.05 --steps 30 --method rk4 --resume "$out/rigid.lpi" \
    --out "$out/bad"
for method in leapfrog strang; do
    rm -rf "$out/r2"; cp -r "$out/r" "$out/r2"
    "$lpi" run rigid-body --dt 0.05 --steps 22 --method $method --resume "$out/rigid.lpi" --out "$out/r2" >/dev/null ||
        { echo "--resume with the checkpoint's method as --method $method: refused"; exit 1; }
done
# --resume reads the interrupted run's CSV back by the rules of the options:
# a field that is no complete finite decimal number, a row with a field too
# few or too many, a step that is no whole number in range, another header
# or a last line cut short fails (1) naming the file and line, the CSV kept.
cp "$out/r/rigid-body.csv" "$out/r.csv"
for edit in '2s/^0,0,[^,]*,/0,0,xyz,/' '3s/,[^,]*$//' '3s/$/,1/' '4s/^[0-9]*,/1e300,/' '4s/^[0-9]*,/nan,/' \
            '4s/^[0-9]*,/2.5,/' '5s/^\([0-9]*\),[^,]*,/\1,0x1p3,/' '6s/,[^,]*,/,inf,/' '7s/,/, /' \
            '1s/^step/stop/' cut; do
    if [ "$edit" = cut ]; then head -c -1 "$out/r.csv"; else sed "$edit" "$out/r.csv"; fi > "$out/r/rigid-body.csv"
    cp "$out/r/rigid-body.csv" "$out/r-bad.csv"
    rc=0; "$lpi" run rigid-body --dt 0.05 --steps 30 --out "$out/r" --resume "$out/rigid.lpi" >/dev/null \
        2>"$out.err" || rc=$?
    [ "$rc" -eq 1 ] && grep -q "rigid-body.csv:[0-9][0-9]*: " "$out.err" ||
        { echo "--resume, the CSV edited by $edit: exit status $rc, expected 1 naming the line"; cat "$out.err"; exit 1; }
    cmp -s "$out/r-bad.csv" "$out/r/rigid-body.csv" || { echo "--resume, the CSV edited by $edit: rewritten"; exit 1; }
done
cp "$out/r.csv" "$out/r/rigid-body.csv"
if [ "$have_sine_euler" = 1 ]; then
    "$lpi" run sine-euler --N 5 --dt 0.05 --steps 4 --out "$out/s" --checkpoint "$out/se5.lpi" >/dev/null
    refused "N = 5, not 7" run sine-euler --N 7 --resume "$out/se5.lpi" --out "$out/bad"
    refused "another" run pendulum --resume "$out/se5.lpi" --out "$out/bad"
    # Another scene's checkpoint of the same system (figure2 is sine-Euler N =
    # 7) where no file of figure2 is there: new files of figure2 start at the
    # checkpoint's step, the other scene's files left as they were.
    "$lpi" run sine-euler --N 7 --dt 0.05 --steps 4 --out "$out/s7" --checkpoint "$out/se7.lpi" >/dev/null
    rm -rf "$out/s7-kept"; cp -r "$out/s7" "$out/s7-kept"
    "$lpi" run figure2 --steps 8 --dt 0.05 --every 2 --resume "$out/se7.lpi" --out "$out/s7" >"$out.out" 2>"$out.err" ||
        { echo "--resume of another scene's checkpoint, no file of its own there: refused"; cat "$out.err"; exit 1; }
    grep -q "new files from step 4" "$out.out" && [ "$(sed -n '2s/,.*//p' "$out/s7/figure2.csv")" = 4 ] ||
        { echo "--resume of another scene's checkpoint: no new files from its step"; cat "$out.out"; exit 1; }
    for file in sine-euler.csv sine-euler.h5 sine-euler; do
        [ ! -e "$out/s7-kept/$file" ] || diff -r "$out/s7-kept/$file" "$out/s7/$file" >/dev/null ||
            { echo "--resume of another scene's checkpoint: $file rewritten"; exit 1; }
    done
    # --wisdom naming the --out directory: refused before either is written.
    refused "is the --out directory" run sine-euler --N 5 --steps 3 --planning measure --wisdom "$out/wout" \
        --out "$out/wout"
    [ ! -e "$out/wout" ] || { echo "--wisdom naming --out: a file was written"; exit 1; }
    refused --planning run sine-euler --planning exhaustive --out "$out/bad"
    refused --planning run sine-euler --planning "" --out "$out/bad"
    refused --planning $rb --planning measure
    # Wisdom that cannot be written or read is a failed file (1), not a bad
    # option; a FIFO is not read (FFTW would wait on it for ever).
    failed "--wisdom" run sine-euler --N 5 --steps 3 --planning measure --wisdom "$out/no-such-dir/w" --out "$out/f"
    echo "not wisdom" > "$out/bad.wisdom"
    failed "--wisdom" run sine-euler --N 5 --steps 3 --wisdom "$out/bad.wisdom" --out "$out/f"
    rm -f "$out/fifo.wisdom"
    if mkfifo "$out/fifo.wisdom" 2>/dev/null; then
        failed "not a regular file" run sine-euler --N 5 --steps 3 --wisdom "$out/fifo.wisdom" --out "$out/f"
    fi
    # Measured plans differ from process to process; shared wisdom makes a
    # second run choose the first run's plans: the same bits.
    for run in 1 2; do
        "$lpi" run sine-euler --N 15 --dt 0.05 --steps 30 --every 10 --planning measure \
            --wisdom "$out/se.wisdom" --out "$out/measured$run" >/dev/null
        [ -s "$out/se.wisdom" ] || { echo "--planning measure --wisdom wrote no wisdom"; exit 1; }
    done
    cmp -s "$out/measured1/sine-euler.csv" "$out/measured2/sine-euler.csv" ||
        { echo "two measured runs sharing --wisdom differ"; exit 1; }
    # The sine-bracket family: SQG, QG (--kd) and topography run, a checkpoint
    # of one Hamiltonian does not resume another, and the roll-up scene runs
    # at a tiny size and writes its CSVs.
    for scene in sqg qg topography; do
        "$lpi" run $scene --N 9 --dt 0.05 --steps 10 --every 5 --out "$out/f" >/dev/null
        rows=$(wc -l < "$out/f/$scene.csv")
        [ "$rows" -eq 4 ] || { echo "lpi run $scene: expected 4 lines, got $rows"; exit 1; }
    done
    for v in 0 -1 nan inf ""; do refused --kd run qg --N 9 --out "$out/bad" --kd "$v"; done
    "$lpi" run qg --N 9 --kd 2 --dt 0.05 --steps 4 --out "$out/q" --checkpoint "$out/qg.lpi" >/dev/null
    refused "Hamiltonian differs" run qg --N 9 --kd 3 --resume "$out/qg.lpi" --out "$out/bad"
    refused "Hamiltonian differs" run sine-euler --N 9 --resume "$out/qg.lpi" --out "$out/bad"
    "$lpi" run qg --N 9 --kd 2 --dt 0.05 --steps 8 --resume "$out/qg.lpi" --out "$out/q" >/dev/null
    refused "takes --N, --steps, --dt and --out only" run rollup --method rk4 --out "$out/bad"
    "$lpi" run rollup --N 9 --steps 30 --dt 0.05 --out "$out/roll" >/dev/null
    rows=$(wc -l < "$out/roll/rollup.csv")
    [ "$rows" -eq 32 ] || { echo "lpi run rollup: expected 32 lines, got $rows"; exit 1; }
    [ "$(head -1 "$out/roll/rollup_spectra.csv")" = "k,enstrophy_t0,enstrophy_t0.05,enstrophy_t0.15,enstrophy_t1.5" ] ||
        { echo "lpi run rollup: spectra header:"; head -1 "$out/roll/rollup_spectra.csv"; exit 1; }
fi

# --checkpoint then --resume with the same options: the CSV (every row, to
# the bit) is the uninterrupted run's, for --every dividing the steps or not.
for every in 10 7; do
    rm -rf "$out/whole" "$out/parts"
    "$lpi" run pendulum --method suzuki-4 --dt 0.05 --steps 53 --every $every --out "$out/whole" >/dev/null
    # A run killed after its checkpoint at row 2 (step 2 * every) left rows past it.
    "$lpi" run pendulum --method suzuki-4 --dt 0.05 --steps $((2 * every)) --every $every \
        --out "$out/parts" --checkpoint "$out/parts.lpi" >/dev/null
    "$lpi" run pendulum --method suzuki-4 --dt 0.05 --steps $((4 * every)) --every $every \
        --out "$out/parts" --checkpoint "$out/later.lpi" >/dev/null
    "$lpi" run pendulum --method suzuki-4 --dt 0.05 --steps 53 --every $every --out "$out/parts" \
        --resume "$out/parts.lpi" >/dev/null
    cmp -s "$out/whole/pendulum.csv" "$out/parts/pendulum.csv" ||
        { echo "--every $every: the resumed CSV differs:"; diff "$out/whole/pendulum.csv" "$out/parts/pendulum.csv"; exit 1; }
done

# A run killed before it wrote its data leaves the data of an earlier run
# there (here of another --inertia and --every): resumed, that data's
# snapshots are not passed off as this run's, whether it has a row at the
# checkpoint's step (--every 1; it was refused as another --dt) or not
# (--every 3; its snapshots were spliced in): only this run's, from the
# checkpoint's step on, are kept (the checkpoint step's taken from the
# resumed state).
for every in 1 3; do
    rm -rf "$out/stale" "$out/stale-b"
    "$lpi" run rigid-body --inertia 1,2,3 --steps 40 --every $every --snapshots 1 --format npy --out "$out/stale" \
        >/dev/null
    "$lpi" run rigid-body --inertia 2,3,5 --steps 10 --every 5 --snapshots 1 --format npy --out "$out/stale-b" \
        --checkpoint "$out/stale.lpi" >/dev/null
    cp "$out/stale-b/rigid-body.csv" "$out/stale/"
    "$lpi" run rigid-body --inertia 2,3,5 --steps 20 --every 5 --snapshots 1 --format npy --out "$out/stale" \
        --resume "$out/stale.lpi" >"$out.out" 2>"$out.err" ||
        { echo "--resume over the data of another run (--every $every): refused"; cat "$out.err"; exit 1; }
    grep -q "another run" "$out.out" ||
        { echo "--resume over the data of another run (--every $every): no note"; cat "$out.out"; exit 1; }
    head -c 128 "$out/stale/rigid-body/snapshot_step.npy" | grep -q "'shape': (3,)" ||
        { echo "--resume over the data of another run (--every $every): its snapshots were kept"; exit 1; }
done
# A CSV replaced since by another run's (another --inertia, the same steps
# and times): its rows up to the checkpoint are not this run's, and would be
# spliced in, the energy errors relative to the other run's energy.
rm -rf "$out/stale"
"$lpi" run rigid-body --inertia 2,3,5 --steps 10 --every 5 --out "$out/stale" --checkpoint "$out/stale.lpi" >/dev/null
"$lpi" run rigid-body --inertia 1,2,3 --steps 10 --every 5 --out "$out/stale" >/dev/null
refused "another run" run rigid-body --inertia 2,3,5 --steps 20 --every 5 --out "$out/stale" --resume "$out/stale.lpi"
# The CSV and the data both reaching the checkpoint but differing before it
# (an energy edited in the CSV, a Casimir, a row deleted): refused (2),
# naming the step and both values, every file left as it was. The data was
# taken for another run's, its snapshots dropped and its rows overwritten
# with the edited CSV's (exit 0); a deleted row was refused as another --every.
rm -rf "$out/edit" "$out/edit-kept"
edit_run="run rigid-body --every 10 --snapshots 2 --format npy --out $out/edit"
"$lpi" $edit_run --steps 100 --checkpoint "$out/edit.lpi" >/dev/null
cp -r "$out/edit" "$out/edit-kept"
edited() {  # edited AWK-PROGRAM MESSAGE-PART: the CSV so edited is refused, nothing rewritten
    awk -F, -v OFS=, "$1" "$out/edit-kept/rigid-body.csv" > "$out/edit/rigid-body.csv"
    cp "$out/edit/rigid-body.csv" "$out/edit.csv"
    refused "$2" $edit_run --steps 200 --resume "$out/edit.lpi"
    cmp -s "$out/edit.csv" "$out/edit/rigid-body.csv" &&
        diff -r "$out/edit-kept/rigid-body" "$out/edit/rigid-body" >/dev/null ||
        { echo "--resume over a CSV that differs from the data: a file was rewritten"; exit 1; }
}
edited 'NR == 4 { d = substr($3, 8, 1); $3 = substr($3, 1, 7) (d + 1) % 10 substr($3, 9) } 1' \
    "differ: at step 20, .*rigid-body.csv has energy 0.5775.*, .*rigid-body has 0.5775.*remove .*rigid-body.csv"
edited 'NR == 5 { $5 = $5 + 1e-9 } 1' "differ: at step 30, .*rigid-body.csv has casimir_0"
edited 'NR != 6' "differ: .*rigid-body has a row at step 40, .*rigid-body.csv has none"
# The run's data in the other --format only: refused (2), naming it, every
# file left as it was. It was ignored ("no data there"): its options not
# taken, its snapshots split across two files.
rm -rf "$out/fmt-probe"
if "$lpi" run rigid-body --steps 1 --format h5 --out "$out/fmt-probe" >/dev/null 2>&1; then
    for formats in "h5 npy" "npy h5"; do
        set -- $formats
        rm -rf "$out/fmt" "$out/fmt-kept"
        "$lpi" run rigid-body --steps 100 --every 10 --snapshots 2 --format $1 --out "$out/fmt" \
            --checkpoint "$out/fmt.lpi" >/dev/null
        cp -r "$out/fmt" "$out/fmt-kept"
        refused "the data of the interrupted run is .*, of --format $1.*resume with --format $1, or move" \
            run rigid-body --steps 200 --format $2 --out "$out/fmt" --resume "$out/fmt.lpi"
        diff -r "$out/fmt-kept" "$out/fmt" >/dev/null ||
            { echo "--resume --format $2 over data of --format $1: a file was written"; exit 1; }
    done
else
    echo "not checked: --resume with the data in the other --format (no HDF5)"
fi
# A CSV with rows but none at the checkpoint's step: a --dt smaller than the
# interrupted run's puts that step past its rows, and a CSV cut short ends
# before it. It was started anew there, every row in it lost (exit 0, a
# note); now refused (2), every file left as it was. With the data, which
# records the run's --dt, the refusal names both. Without the CSV, data at
# another --dt (its rows' times not this --dt's steps) is refused too: its
# snapshots were kept, spliced to this run's at half the step size.
rm -rf "$out/dt" "$out/dt-kept"
set -- run rigid-body --every 10 --snapshots 1 --format npy --out "$out/dt"
"$lpi" "$@" --steps 40 --checkpoint "$out/dt.lpi" >/dev/null
cp -r "$out/dt" "$out/dt-kept"
refused "--dt 0.005, but the interrupted run's is 0.01" "$@" --steps 100 --dt 0.005 --resume "$out/dt.lpi"
mv "$out/dt/rigid-body" "$out/dt-data"
refused "has no row at step 80" "$@" --steps 100 --dt 0.005 --resume "$out/dt.lpi"
mv "$out/dt-data" "$out/dt/rigid-body"
diff -r "$out/dt-kept" "$out/dt" >/dev/null || { echo "--resume with a smaller --dt: a file was rewritten"; exit 1; }
# A CSV cut short whose rows are the data's: the data gives the rows.
sed -i '4,$d' "$out/dt/rigid-body.csv"
"$lpi" "$@" --steps 40 --resume "$out/dt.lpi" >"$out.out" ||
    { echo "--resume over a CSV cut short, the data whole: refused"; exit 1; }
grep -q "ends before the checkpoint's step: its rows up to step 40 are taken from" "$out.out" &&
    cmp -s "$out/dt-kept/rigid-body.csv" "$out/dt/rigid-body.csv" ||
    { echo "--resume over a CSV cut short: not the rows of the data"; cat "$out.out"; exit 1; }
rm "$out/dt/rigid-body.csv"
refused "another --dt" "$@" --steps 100 --dt 0.005 --resume "$out/dt.lpi"
diff -r "$out/dt-kept/rigid-body" "$out/dt/rigid-body" >/dev/null ||
    { echo "--resume with a smaller --dt over data alone: the data was rewritten"; exit 1; }
# The CSV and the data hold two copies of the rows: resumed without the CSV,
# the rows up to the checkpoint come from the data (they were dropped, the
# energy error made relative to the checkpoint's step), and the run is the
# uninterrupted one.
rm -rf "$out/two" "$out/two-ref"
set -- run rigid-body --every 10 --out "$out/two"
"$lpi" "$@" --steps 100 --checkpoint "$out/two.lpi" >/dev/null
mv "$out/two/rigid-body.csv" "$out/two.csv"
"$lpi" "$@" --steps 200 --resume "$out/two.lpi" >/dev/null
"$lpi" run rigid-body --every 10 --steps 200 --out "$out/two-ref" >/dev/null
cmp -s "$out/two-ref/rigid-body.csv" "$out/two/rigid-body.csv" ||
    { echo "--resume without the CSV: not the uninterrupted run's rows"; exit 1; }
# Into an --out without a file of the run (a new or empty directory), new
# files start at the checkpoint's step, the energy error relative to it (a
# note says so): the uninterrupted run's rows from that step on. The
# checkpoint does not record --dt and --every, and no file there does: both
# must be given (the scene's defaults went on at another step, the times
# wrong: here --dt 0.02 took the checkpoint's t = 1 for step 50).
rm -rf "$out/two-none"; mkdir "$out/two-none"
refused "does not record the interrupted run's --dt and --every" run rigid-body --every 10 --steps 200 \
    --out "$out/two-none" --resume "$out/two.lpi"
refused "does not record the interrupted run's --dt and --every" run rigid-body --dt 0.01 --steps 200 \
    --out "$out/two-none" --resume "$out/two.lpi"
refused "not a whole number of steps of 0.0299" run rigid-body --dt 0.03 --every 10 --steps 200 \
    --out "$out/two-none" --resume "$out/two.lpi"
[ -z "$(ls "$out/two-none")" ] || { echo "a refused --resume into an empty --out wrote files"; exit 1; }
"$lpi" run rigid-body --dt 0.01 --every 10 --steps 200 --out "$out/two-none" --resume "$out/two.lpi" >"$out.out" 2>"$out.err" ||
    { echo "--resume into an empty --out: refused"; cat "$out.err"; exit 1; }
grep -q "new files from step 100, the energy error relative to that step" "$out.out" ||
    { echo "--resume into an empty --out: no note"; cat "$out.out"; exit 1; }
awk -F, 'NR > 1 && $1 >= 100' "$out/two-ref/rigid-body.csv" | cut -d, -f1-3,5- > "$out/two-tail"
tail -n +2 "$out/two-none/rigid-body.csv" | cut -d, -f1-3,5- | cmp -s - "$out/two-tail" &&
    [ "$(sed -n '2p' "$out/two-none/rigid-body.csv" | cut -d, -f1,4)" = 100,0 ] ||
    { echo "--resume into an empty --out: not the rows from step 100"; head -3 "$out/two-none/rigid-body.csv"; exit 1; }
# A file of the run there, but neither copy reaching the checkpoint (a CSV
# cut before it, no data): refused, the file left as it was.
rm -rf "$out/two-cut"; mkdir "$out/two-cut"
head -4 "$out/two.csv" > "$out/two-cut/rigid-body.csv"; cp "$out/two-cut/rigid-body.csv" "$out/two-cut.csv"
refused "has no row at step 100" run rigid-body --every 10 --steps 200 --out "$out/two-cut" --resume "$out/two.lpi"
cmp -s "$out/two-cut.csv" "$out/two-cut/rigid-body.csv" && [ "$(ls "$out/two-cut")" = rigid-body.csv ] ||
    { echo "--resume over a CSV cut short, no data: a file was written"; exit 1; }
# Another --dt (by 1e-11, within the old margin), --every or --snapshots than
# the interrupted run's: refused (their rows were spliced, the library's
# calls ending elsewhere, so not bit for bit), with or without the data.
"$lpi" "$@" --steps 100 --checkpoint "$out/two.lpi" >/dev/null
cp -r "$out/two" "$out/two-kept"
refused "--dt" "$@" --steps 200 --dt 0.0100000000001 --resume "$out/two.lpi"
refused "--every" "$@" --steps 200 --every 7 --resume "$out/two.lpi"
refused "--snapshots" "$@" --steps 200 --snapshots 3 --resume "$out/two.lpi"
diff -r "$out/two-kept" "$out/two" >/dev/null || { echo "a refused --resume rewrote a file"; exit 1; }
# Extended with a larger --steps and no --every (whose default, about 100
# rows, is then another) nor --snapshots: the interrupted run's are taken,
# and the run ends bit for bit where the uninterrupted run of the larger
# --steps with them ends, CSV and data; without the data, the CSV's rows
# give --every. Without --dt, a run of another step than the scene's takes
# the data's (it was refused as another --dt).
rm -rf "$out/ext" "$out/ext-ref" "$out/ext-csv"
"$lpi" run rigid-body --steps 1000 --snapshots 5 --format npy --out "$out/ext" --checkpoint "$out/ext.lpi" >/dev/null
cp -r "$out/ext" "$out/ext-csv"; rm -r "$out/ext-csv/rigid-body"
"$lpi" run rigid-body --steps 2000 --format npy --out "$out/ext" --resume "$out/ext.lpi" >"$out.out" 2>"$out.err" ||
    { echo "--resume with a larger --steps, no --every: refused"; cat "$out.err"; exit 1; }
"$lpi" run rigid-body --steps 2000 --every 10 --snapshots 5 --format npy --out "$out/ext-ref" >/dev/null
cmp -s "$out/ext-ref/rigid-body.csv" "$out/ext/rigid-body.csv" &&
    diff -r "$out/ext-ref/rigid-body" "$out/ext/rigid-body" >/dev/null ||
    { echo "--resume with a larger --steps, no --every: not the uninterrupted run's CSV and data"; exit 1; }
"$lpi" run rigid-body --steps 2000 --format npy --out "$out/ext-csv" --resume "$out/ext.lpi" >/dev/null 2>"$out.err" ||
    { echo "--resume with a larger --steps, no --every, no data: refused"; cat "$out.err"; exit 1; }
cmp -s "$out/ext-ref/rigid-body.csv" "$out/ext-csv/rigid-body.csv" ||
    { echo "--resume with a larger --steps, no --every, no data: not the uninterrupted run's CSV"; exit 1; }
refused "--every 20, but the interrupted run's is 10" run rigid-body --steps 2000 --every 20 --format npy \
    --out "$out/ext" --resume "$out/ext.lpi"
refused "--snapshots 10, but the interrupted run's is 5" run rigid-body --steps 2000 --snapshots 10 --format npy \
    --out "$out/ext" --resume "$out/ext.lpi"
rm -rf "$out/ext" "$out/ext-ref"
"$lpi" run rigid-body --dt 0.02 --steps 100 --every 10 --format npy --out "$out/ext" --checkpoint "$out/ext.lpi" \
    >/dev/null
cp "$out/ext/rigid-body.csv" "$out/ext.csv"
"$lpi" run rigid-body --steps 200 --format npy --out "$out/ext" --resume "$out/ext.lpi" >"$out.out" 2>"$out.err" ||
    { echo "--resume of a run of another --dt, no --dt: refused"; cat "$out.err"; exit 1; }
"$lpi" run rigid-body --dt 0.02 --steps 200 --every 10 --format npy --out "$out/ext-ref" >/dev/null
cmp -s "$out/ext-ref/rigid-body.csv" "$out/ext/rigid-body.csv" &&
    diff -r "$out/ext-ref/rigid-body" "$out/ext/rigid-body" >/dev/null ||
    { echo "--resume of a run of another --dt, no --dt: not the uninterrupted run's"; exit 1; }
rm -r "$out/ext/rigid-body"; cp "$out/ext.csv" "$out/ext/rigid-body.csv"
refused "another --dt" run rigid-body --steps 200 --format npy --out "$out/ext" --resume "$out/ext.lpi"
# A run that ends off the --every grid (the default --every 12 of 1234 steps)
# is extended bit for bit, and so is the extension: its final checkpoint is
# the last row on the grid, and the end row after it is replaced. The end's
# state was saved: the extension split the last call of the uninterrupted
# run, spliced the end row in (1224, 1234, 1236) and could not be resumed
# again (refused as another --every).
rm -rf "$out/off" "$out/off-ref"
set -- run pendulum --format npy --out "$out/off" --checkpoint "$out/off.lpi"
"$lpi" "$@" --steps 1234 >"$out.out"
grep -q "checkpoint: .*off.lpi (step 1224, the last row on the --every grid" "$out.out" ||
    { echo "a run ending off the grid: its checkpoint is not the last row on the grid"; cat "$out.out"; exit 1; }
for steps in 3000 5000; do
    "$lpi" "$@" --steps $steps --resume "$out/off.lpi" >/dev/null 2>"$out.err" ||
        { echo "extended from a run ending off the grid, to $steps steps: refused"; cat "$out.err"; exit 1; }
done
"$lpi" run pendulum --format npy --steps 5000 --every 12 --out "$out/off-ref" >/dev/null
cmp -s "$out/off-ref/pendulum.csv" "$out/off/pendulum.csv" &&
    diff -r "$out/off-ref/pendulum" "$out/off/pendulum" >/dev/null ||
    { echo "1234, 3000, then 5000 steps: not the uninterrupted run's CSV and data"; exit 1; }
# Snapshots too: 25 steps (rows 0, 10, 20, 25), extended to 50, are the
# uninterrupted run's (rows 0, 10, ..., 50; snapshots at steps 0 and 30).
if [ "$have_sine_euler" = 1 ]; then
    rm -rf "$out/off" "$out/off-ref"
    set -- run sine-euler --N 7 --every 10 --snapshots 3 --format npy
    "$lpi" "$@" --steps 25 --out "$out/off" --checkpoint "$out/off.lpi" >/dev/null
    "$lpi" "$@" --steps 50 --out "$out/off" --resume "$out/off.lpi" >/dev/null
    "$lpi" "$@" --steps 50 --out "$out/off-ref" >/dev/null
    cmp -s "$out/off-ref/sine-euler.csv" "$out/off/sine-euler.csv" &&
        diff -r "$out/off-ref/sine-euler" "$out/off/sine-euler" >/dev/null ||
        { echo "sine-euler 25 steps extended to 50: not the uninterrupted run's CSV and data"; exit 1; }
fi
# Every value of the CSV reads back as written (the energy error had 7 digits).
awk -F, 'NR > 2 && length($4) < 12 { bad = 1 } END { exit bad }' "$out/two/rigid-body.csv" ||
    { echo "the CSV's energy error is not written in full"; exit 1; }
# A run certain to run out of memory keeping its rows is refused before its
# first step (it failed after all of them, its work lost). Under
# AddressSanitizer, whose shadow memory no address-space limit leaves room
# for, the build without it checks this.
if ldd "$lpi" 2>/dev/null | grep -q libasan; then
    echo "check_lpi_run: the memory check of rows left to the build without AddressSanitizer"
else
    rc=0; (ulimit -v 1000000; exec timeout 30 "$lpi" run rigid-body --steps 100000000 --every 1 --snapshots 0 \
        --out "$out/huge-rows") >"$out.out" 2>"$out.err" || rc=$?
    [ "$rc" -eq 1 ] && grep -q "more than is available: write rows less often (--every)" "$out.err" &&
        ! grep -q "steps 0 to" "$out.out" || { echo "rows past the memory: exit status $rc"; cat "$out.err"; exit 1; }
fi
# Data that is there but cannot be read back (cut short, not data at all,
# or a header claiming more than the readers' cap of 2^28 values) is not
# replaced by the resumed run, which dropped it with a note and lost the
# snapshots in it: refused (1) naming the file, every file left as it was.
rm -rf "$out/unread"
set -- rigid-body --every 5 --snapshots 1 --format npy --out "$out/unread"
"$lpi" run "$@" --steps 20 --checkpoint "$out/unread.lpi" >/dev/null
data="$out/unread/rigid-body"
cp "$data/state.npy" "$out/state.npy"
dict="{'descr': '<f8', 'fortran_order': False, 'shape': (100000000, 3), }"
pad=$((128 - 10 - ${#dict} - 1))
unreadable() {  # unreadable FILE MESSAGE-PART lpi-run-arguments...: --resume refused, the files kept
    file=$1 what=$2; shift 2
    (cd "$out/unread" && find . -type f -exec md5sum {} + > "$out/unread.md5")
    rc=0; "$lpi" run "$@" --steps 30 --resume "$out/unread.lpi" >/dev/null 2>"$out.err" || rc=$?
    [ "$rc" -eq 1 ] && grep -q "$file cannot be read back ($what" "$out.err" ||
        { echo "--resume, $file damaged ($what): exit status $rc, expected 1"; cat "$out.err"; exit 1; }
    (cd "$out/unread" && md5sum -c --quiet "$out/unread.md5") ||
        { echo "--resume, $file damaged ($what): a file was replaced"; exit 1; }
}
for damage in cut text claim; do
    case $damage in
    cut) head -c 100 "$out/state.npy" ;;
    text) echo "not data" ;;
    claim) printf '\223NUMPY\001\000\166\000%s%*s\n' "$dict" "$pad" ""; head -c 48 /dev/zero ;;
    esac > "$data/state.npy"
    case $damage in cut) what=truncated ;; text) what="not a NumPy" ;; claim) what="more than 2^28 values" ;; esac
    unreadable "$data" "state.npy: $what" "$@"
done
cp "$out/state.npy" "$data/state.npy"
if "$lpi" run rigid-body --steps 1 --format h5 --out "$out/probe" >/dev/null 2>&1; then
    rm -rf "$out/unread"
    set -- rigid-body --every 5 --snapshots 1 --format h5 --out "$out/unread"
    "$lpi" run "$@" --steps 20 --checkpoint "$out/unread.lpi" >/dev/null
    head -c 3000 "$out/unread/rigid-body.h5" > "$out/cut.h5"; mv "$out/cut.h5" "$out/unread/rigid-body.h5"
    unreadable "$out/unread/rigid-body.h5" "HDF5 cannot open" "$@"
    # /state's dimensions (5, 3), and its maximum ones, made (10^8, 3): over the cap.
    "$lpi" run "$@" --steps 20 --checkpoint "$out/unread.lpi" >/dev/null
    zeros='\x00\x00\x00\x00\x00\x00\x00'
    if at=$(LC_ALL=C grep -obUaP "\\x05$zeros\\x03$zeros" "$out/unread/rigid-body.h5" | cut -d: -f1) &&
        [ -n "$at" ]; then
        for offset in $at; do
            printf '\000\341\365\005\000\000\000\000' |
                dd of="$out/unread/rigid-body.h5" bs=1 seek="$offset" conv=notrunc 2>/dev/null
        done
        unreadable "$out/unread/rigid-body.h5" "state has more than 2^28 values" "$@"
    fi
fi
# Moved aside, the run resumes without them, as it does without data.
mv "$out/unread/rigid-body.h5" "$out/unread.h5" 2>/dev/null || mv "$data" "$out/unread.npy"
"$lpi" run "$@" --steps 30 --resume "$out/unread.lpi" >"$out.out" 2>"$out.err" ||
    { echo "--resume, the damaged data moved aside: refused"; cat "$out.err"; exit 1; }
grep -q "no data there" "$out.out" || { echo "--resume without data: no note"; cat "$out.out"; exit 1; }

# Ctrl-C: SIGINT stops a long run through the library's observer within a
# few steps, even inside one long lpi_step call: status 130, a complete last
# row at the step where it stopped, and the checkpoint of the last row on the
# --every grid (the start of the interrupted call: resuming in the middle of a
# call would split it, and its merged flows, in two). The same command,
# resumed, ends bit for bit where the uninterrupted run ends (a few rows
# further on, at a step that is not a multiple of --every): CSV and data.
if [ "$have_sine_euler" = 1 ]; then
    long="sine-euler --N 9 --snapshots 5"; scene=sine-euler; per_row=1000
else
    long="rigid-body --snapshots 5"; scene=rigid-body; per_row=100000
fi
csv=$scene.csv
interrupt() {  # interrupt EVERY FORMAT: runs, stops it, checks; sets stop, held
    rm -rf "$out/int" "$out/int.lpi"
    "$lpi" run $long --dt 0.01 --steps 1000000000 --every "$1" --format "$2" --out "$out/int" \
        --checkpoint "$out/int.lpi" >"$out/int.out" &
    pid=$!
    # The first row is written once the handler is in place; then let it run.
    while [ ! -f "$out/int/$csv" ] || [ "$(wc -l < "$out/int/$csv")" -lt 2 ]; do
        kill -0 $pid 2>/dev/null || { echo "the long run ended early"; exit 1; }
        sleep 0.05
    done
    sleep 0.3
    kill -INT $pid
    waited=0
    while kill -0 $pid 2>/dev/null && [ $waited -lt 300 ]; do sleep 0.1; waited=$((waited + 1)); done
    kill -0 $pid 2>/dev/null && { kill -KILL $pid; echo "SIGINT did not stop the run within 30 s (--every $1)"; exit 1; }
    rc=0; wait $pid || rc=$?
    [ "$rc" -eq 130 ] || { echo "SIGINT: exit status $rc, expected 130"; exit 1; }
    [ "$(tail -c 1 "$out/int/$csv" | od -An -c | tr -d ' ')" = '\n' ] || { echo "SIGINT: last row cut"; exit 1; }
    fields=$(head -n 1 "$out/int/$csv" | tr -cd , | wc -c)
    [ "$(tail -n 1 "$out/int/$csv" | tr -cd , | wc -c)" -eq "$fields" ] || { echo "SIGINT: last row incomplete"; exit 1; }
    stop=$(tail -n 1 "$out/int/$csv" | cut -d, -f1)
    [ "$stop" -gt 0 ] || { echo "SIGINT: no step made before the stop"; exit 1; }
    held=$(sed -n 's/.* holds step \([0-9]*\) .*/\1/p' "$out/int.out")
    [ "$held" = $((stop - stop % $1)) ] ||
        { echo "SIGINT at step $stop (--every $1): the checkpoint holds step '$held'"; cat "$out/int.out"; exit 1; }
}
same_data() {  # same_data FORMAT WHAT: the data of int/ and ref/ are the same bytes
    if [ "$1" = h5 ]; then
        cmp -s "$out/ref/$scene.h5" "$out/int/$scene.h5" || { echo "$2: the HDF5 data differs"; exit 1; }
    else
        diff -r "$out/ref/$scene" "$out/int/$scene" >/dev/null || { echo "$2: the .npy data differs"; exit 1; }
    fi
}
formats=npy
"$lpi" run rigid-body --steps 1 --format h5 --out "$out/probe" >/dev/null 2>&1 && formats="npy h5"
for format in $formats; do
    for every in $per_row $((per_row * 7 / 9 + 1)); do
        interrupt $every $format
        end=$((stop + 2 * every + 5))
        rm -rf "$out/ref"
        "$lpi" run $long --dt 0.01 --steps $end --every $every --format $format --out "$out/int" \
            --checkpoint "$out/int.lpi" --resume "$out/int.lpi" >/dev/null
        "$lpi" run $long --dt 0.01 --steps $end --every $every --format $format --out "$out/ref" >/dev/null
        cmp -s "$out/ref/$csv" "$out/int/$csv" ||
            { echo "interrupted at $stop (--every $every) and resumed: the CSV differs"; diff "$out/ref/$csv" "$out/int/$csv" | tail -4; exit 1; }
        same_data $format "interrupted at $stop (--every $every) and resumed"
    done
done
# One call of 10^9 steps (minutes): SIGINT still stops it at once, the
# checkpoint is the run's start, and the resumed run is the uninterrupted one.
interrupt 1000000000 npy
[ "$held" -eq 0 ] || { echo "one long call: the checkpoint holds step $held, not 0"; exit 1; }
rm -rf "$out/ref"
"$lpi" run $long --dt 0.01 --steps $((stop + 3)) --every 1000000000 --format npy --out "$out/int" \
    --resume "$out/int.lpi" >/dev/null
"$lpi" run $long --dt 0.01 --steps $((stop + 3)) --every 1000000000 --format npy --out "$out/ref" >/dev/null
cmp -s "$out/ref/$csv" "$out/int/$csv" || { echo "one long call, interrupted and resumed: the CSV differs"; exit 1; }
same_data npy "one long call, interrupted and resumed"
# SIGTERM once the steps are done, while gnuplot draws the snapshots (the
# script is written just before it starts): it was ignored (exit status 0),
# and a Ctrl-C, which reaches gnuplot too, failed the run as gnuplot's
# failure (1). Now gnuplot is ended and the run exits 143, keeping the old
# images and no temporary file.
if [ "$have_sine_euler" = 1 ] && command -v gnuplot >/dev/null 2>&1; then
    rm -rf "$out/draw"
    "$lpi" run sine-euler --N 9 --steps 600 --every 1 --snapshots 1 --out "$out/draw" >"$out/draw.out" 2>&1 &
    pid=$!
    waited=0
    while [ ! -f "$out/draw/sine-euler_vorticity.gp" ] && [ $waited -lt 600 ]; do sleep 0.05; waited=$((waited + 1)); done
    sleep 0.2
    kill -TERM $pid
    rc=0; wait $pid || rc=$?
    [ "$rc" -eq 143 ] && grep -q "^interrupted .*images were drawn" "$out/draw.out" ||
        { echo "SIGTERM while the images were drawn: exit status $rc, expected 143"; cat "$out/draw.out"; exit 1; }
    ! ls -a "$out/draw" | grep -q "^\.lpi-" || { echo "SIGTERM while the images were drawn: temporaries left"; exit 1; }
else
    echo "not checked: a signal while the images are drawn (no sine-Euler or no gnuplot)"
fi
echo "lpi run: bad options refused, failures reported, SIGINT and --resume continue to the bit"
