#!/bin/sh
# check_lpi_files.sh LPI OUTDIR
# Nothing lpi writes is lost, and no failure passes for success:
#  - gnuplot runs without a shell: an --out with quotes and ';' runs nothing;
#  - a plot gnuplot fails to draw (a gnuplot that fails, an image path that
#    is a directory) fails lpi run, report figure2, sine-euler-long and
#    rollup naming the file, and so does an image gnuplot leaves empty or
#    cut short while exiting 0 (the old images kept); without gnuplot the
#    plots are skipped, said so; lpi report whose CSV cannot be written
#    fails before its work, not saying where its files are, and one whose
#    plot or any file fails keeps all of the scene's old files;
#  - a write that fails (RLIMIT_FSIZE, as a full disk) keeps the old CSV,
#    the old .npy set and the old HDF5 file whole, names the file and the
#    reason, exits 1 (no crash, also with SIGXFSZ at its default action, and
#    so does standard output) and leaves no temporary file; a replaced file
#    keeps its mode, a new one gets the umask's; a FIFO where an output
#    goes is refused, not replaced;
#  - a failure after the run has gathered data (a checkpoint save or the
#    CSV failing mid-run, the CSV at the end) still writes the data, and a
#    run killed by SIGKILL resumes from the CSV and data written with its
#    last checkpoint to the uninterrupted run's files;
#  - --checkpoint that cannot work (moments) or names an output of the run
#    is refused (2) and one that fails leaves the old CSV; --resume with
#    another --dt is refused (2); --init refuses a FIFO (1) at once;
#  - H(0) = 0 gives an absolute energy error, labelled, not -nan;
#  - rollup stops on SIGINT (130) and SIGTERM (143) with its CSV written;
#    lpi report too, keeping the last report's files of the scene.
# The sine-Euler parts are left out (and named) in a build without FFTW.
set -eu
lpi="$1"; out="$2"
case $lpi in /*) ;; *) lpi="$(pwd)/$lpi" ;; esac
rm -rf "$out"; mkdir -p "$out"
out=$(cd "$out" && pwd)
fail() { echo "FAIL: $*"; exit 1; }
expect() {  # expect STATUS MESSAGE-PART lpi-arguments...: exit status and a message on stderr
    want=$1 what=$2; shift 2
    rc=0
    timeout 60 "$lpi" "$@" >"$out/stdout" 2>"$out/stderr" || rc=$?
    [ "$rc" -eq "$want" ] || { cat "$out/stderr"; fail "lpi $*: exit status $rc, expected $want"; }
    grep -q -e "$what" "$out/stderr" || { cat "$out/stderr"; fail "lpi $*: no message with '$what'"; }
}
no_temporaries() {  # no_temporaries DIR: no temporary file of a write left behind
    ! ls -a "$1" | grep -q '^\.lpi-' || fail "temporary files left in $1: $(ls -a "$1")"
}
have_se=1
"$lpi" run sine-euler --N 5 --steps 1 --out "$out/probe" >/dev/null 2>&1 || have_se=0
[ "$have_se" = 1 ] || echo "not checked: the plots, .npy sets, H(0) = 0 and rollup (no sine-Euler in this build)"

# Fake gnuplots: one that records how it was run and draws a minimal PNG or
# SVG for each "set output" of its script (by the terminal set before it),
# one that fails, two that exit 0 with the images unfinished as a full disk
# leaves them (empty; SVGs cut short), none at all.
mkdir -p "$out/ok-gnuplot" "$out/bad-gnuplot" "$out/empty-gnuplot" "$out/cut-gnuplot" "$out/no-gnuplot"
cat > "$out/ok-gnuplot/gnuplot" <<'EOF'
#!/bin/sh
{ pwd; echo "$#"; printf '%s\n' "$@"; } > "$FAKE_LOG"
sed -n -e "s/^set terminal \([a-z]*\).*/\1/p" -e "s/^set output '\(.*\)'\$/\1/p" "$1" |
while IFS= read -r terminal && IFS= read -r image; do
    case ${FAKE_IMAGES:-whole}.$terminal in
        empty.*) : > "$image" ;;
        *.pngcairo) printf '\211PNG\r\n\032\n\000\000\000\000IEND\256B`\202' > "$image" ;;
        cut.svg) printf '<svg>\n' > "$image" ;;
        *.svg) printf '<svg>\n</svg>\n\n' > "$image" ;;
    esac
done
EOF
printf '#!/bin/sh\necho "fake gnuplot: cannot draw" >&2\nexit 1\n' > "$out/bad-gnuplot/gnuplot"
for kind in empty cut; do
    printf '#!/bin/sh\nFAKE_IMAGES=%s exec "%s" "$@"\n' $kind "$out/ok-gnuplot/gnuplot" > "$out/$kind-gnuplot/gnuplot"
done
chmod +x "$out"/*-gnuplot/gnuplot
export FAKE_LOG="$out/gnuplot.log"
ok_path="$out/ok-gnuplot:$PATH"; bad_path="$out/bad-gnuplot:$PATH"

if [ "$have_se" = 1 ]; then
    # No shell: the directory name reaches gnuplot (run in it) as no command.
    inject="x';touch INJECTED;'y"
    (cd "$out" && PATH="$ok_path" "$lpi" run sine-euler --N 5 --steps 2 --out "$inject" >/dev/null) ||
        fail "lpi run with a quote in --out"
    [ ! -e "$out/INJECTED" ] || fail "--out \"$inject\" ran a shell command"
    [ "$(sed -n 1p "$out/gnuplot.log")" = "$out/$inject" ] && [ "$(sed -n 2p "$out/gnuplot.log")" = 1 ] ||
        { cat "$out/gnuplot.log"; fail "gnuplot was not run in the output directory with one argument"; }
    if command -v gnuplot >/dev/null 2>&1; then
        (cd "$out" && "$lpi" run sine-euler --N 5 --steps 2 --out "y';system('touch INJECTED2');'z" >/dev/null) ||
            fail "lpi run with gnuplot's quotes in --out"
        [ ! -e "$out/INJECTED2" ] || fail "a gnuplot command in --out was run"
    fi
    # A plot that is not drawn fails the command, naming the file.
    PATH="$bad_path" expect 1 "sine-euler_vorticity.gp.*fake gnuplot" run sine-euler --N 5 --steps 2 --out "$out/p1"
    PATH="$bad_path" expect 1 "figure2.gp.*fake gnuplot" report figure2 --out "$out/p2"
    PATH="$bad_path" expect 1 "sine-euler-long.gp.*fake gnuplot" report sine-euler-long --N 5 --T 5 --out "$out/p3"
    PATH="$bad_path" expect 1 "rollup.gp.*fake gnuplot" run rollup --N 5 --steps 3 --out "$out/p4"
    # An image gnuplot leaves unfinished (exiting 0 all the same) fails the
    # command, naming it, and every old image is kept.
    PATH="$ok_path" "$lpi" run sine-euler --N 5 --steps 2 --out "$out/p8" >/dev/null
    PATH="$ok_path" "$lpi" run rollup --N 5 --steps 3 --out "$out/p9" >/dev/null
    (cd "$out" && md5sum p8/*.png p8/*.svg p9/*.png p9/*.svg > "$out/images.md5")
    PATH="$out/empty-gnuplot:$PATH" expect 1 "sine-euler_vorticity_000000.png (it is empty" run sine-euler --N 5 --steps 2 \
        --out "$out/p8"
    PATH="$out/cut-gnuplot:$PATH" expect 1 "rollup.svg (the SVG is cut short" run rollup --N 5 --steps 3 --out "$out/p9"
    (cd "$out" && md5sum -c --quiet "$out/images.md5") || fail "an unfinished image replaced a good one"
    no_temporaries "$out/p8"; no_temporaries "$out/p9"
    # A report whose plot fails, or one of whose files cannot be written,
    # keeps every file of the last report: no new CSV beside old images.
    for scene in figure2 pendulum "sine-euler-long --N 5 --T 5"; do
        name=${scene%% *}
        PATH="$ok_path" "$lpi" report $scene --out "$out/p11" >/dev/null
        (cd "$out/p11" && md5sum $(ls | grep -e "^$name[._]") > "$out/report.md5")
        PATH="$bad_path" expect 1 "$name.gp.*fake gnuplot" report $scene --out "$out/p11"
        (cd "$out/p11" && md5sum -c --quiet "$out/report.md5") || fail "a failed plot of $name replaced its files"
        no_temporaries "$out/p11"
    done
    # (sine-euler-long's second CSV, its history, stands for a work-precision
    # scene's energy CSV: the same PlotScript writes both, in 1/30 the time.)
    rm "$out/p11/sine-euler-long_history.csv"; mkdir "$out/p11/sine-euler-long_history.csv"
    (cd "$out/p11" && md5sum sine-euler-long.csv sine-euler-long.gp sine-euler-long_*.png sine-euler-long_*.svg \
        > "$out/report.md5")
    PATH="$ok_path" expect 1 "sine-euler-long_history.csv.*directory" report sine-euler-long --N 5 --T 5 --out "$out/p11"
    (cd "$out/p11" && md5sum -c --quiet "$out/report.md5") ||
        fail "a report whose second CSV could not be written replaced its other files"
    no_temporaries "$out/p11"
    # lpi report whose CSV cannot be written fails before the work, and says
    # nothing of files written.
    mkdir -p "$out/p10/figure2.csv"
    expect 1 "figure2.csv.*directory" report figure2 --out "$out/p10"
    ! grep -q -e "^== figure2" -e "files are in" "$out/stdout" ||
        { cat "$out/stdout"; fail "lpi report with an unwritable CSV ran, or said its files were written"; }
    mkdir -p "$out/p5/figure2.png" "$out/p6/sine-euler_vorticity_000000.png"
    PATH="$ok_path" expect 1 "figure2.png.*directory" report figure2 --out "$out/p5"
    PATH="$ok_path" expect 1 "sine-euler_vorticity_000000.png.*directory" run sine-euler --N 5 --steps 2 --out "$out/p6"
    # The script and images are the data's: images of steps the new data has
    # no snapshot of are removed, and SCENE_vorticity.gp is written with the data
    # (gnuplot reads it at a byte offset: a script or images of the last run
    # drew garbage, or another run's snapshots), also without gnuplot.
    PATH="$ok_path" "$lpi" run sine-euler --N 5 --steps 10 --every 1 --snapshots 5 --out "$out/p12" >/dev/null
    PATH="$out/no-gnuplot" "$lpi" run sine-euler --N 7 --steps 9 --every 1 --snapshots 3 --out "$out/p12" >/dev/null
    [ "$(cd "$out/p12" && echo sine-euler_vorticity_*)" = \
        "sine-euler_vorticity_000000.png sine-euler_vorticity_000000.svg" ] ||
        fail "images of another run's snapshots left: $(ls "$out/p12")"
    grep -q "sine-euler_vorticity_000009.png" "$out/p12/sine-euler_vorticity.gp" ||
        fail "sine-euler_vorticity.gp is not written for the data of the run"
    PATH="$ok_path" "$lpi" run sine-euler --N 5 --steps 2 --snapshots 0 --out "$out/p12" >/dev/null
    [ -z "$(ls "$out/p12" | grep -e vorticity)" ] || fail "a run without snapshots left images or sine-euler_vorticity.gp"
    # Without gnuplot the plots are skipped, and the run says so.
    rc=0; PATH="$out/no-gnuplot" "$lpi" run sine-euler --N 5 --steps 2 --out "$out/p7" >"$out/stdout" 2>&1 || rc=$?
    [ "$rc" -eq 0 ] && grep -q "gnuplot not found" "$out/stdout" ||
        { cat "$out/stdout"; fail "without gnuplot: exit status $rc"; }
fi

# lpi report stops at SIGINT (130) and SIGTERM (143): a signal while gnuplot
# draws (a slow fake one, started once the work is done) ends gnuplot, and
# the scene's files stay the last report's, with no temporary file left. It
# used to die by the signal, its temporaries left and gnuplot drawing on.
mkdir -p "$out/slow-gnuplot"
printf '#!/bin/sh\n: > "%s/slow.started"\nexec sleep 60\n' "$out" > "$out/slow-gnuplot/gnuplot"
chmod +x "$out/slow-gnuplot/gnuplot"
# sine-euler-long at N = 5 takes 0.2 s, the pendulum's sweep 6 (without FFTW).
sig_scene="sine-euler-long --N 5 --T 5"
[ "$have_se" = 1 ] || sig_scene=pendulum
PATH="$out/ok-gnuplot:$PATH" "$lpi" report $sig_scene --out "$out/sig" >/dev/null
(cd "$out/sig" && md5sum * > "$out/sig.md5")
for signal in INT TERM; do
    rm -f "$out/slow.started"
    PATH="$out/slow-gnuplot:$PATH" "$lpi" report $sig_scene --out "$out/sig" >"$out/sig.out" 2>&1 &
    pid=$!
    waited=0
    while [ ! -f "$out/slow.started" ] && [ $waited -lt 1200 ]; do sleep 0.05; waited=$((waited + 1)); done
    kill -$signal $pid
    rc=0; wait $pid || rc=$?
    want=130; [ $signal = TERM ] && want=143
    [ "$rc" -eq $want ] && grep -q "^interrupted: ${sig_scene%% *} was not finished" "$out/sig.out" ||
        { cat "$out/sig.out"; fail "lpi report, SIG$signal while gnuplot draws: exit status $rc, expected $want"; }
    (cd "$out/sig" && md5sum -c --quiet "$out/sig.md5") || fail "lpi report, SIG$signal: the last report's files changed"
    no_temporaries "$out/sig"
done

# A write that fails keeps the old file whole and says why. RLIMIT_FSIZE
# (SIGXFSZ ignored: the write fails with EFBIG) stands for a full disk; the
# limit (40 blocks of 512 or 1024 bytes) is above the old files, below the new.
limited() { (trap '' XFSZ; ulimit -f 40; exec "$lpi" "$@"); }
"$lpi" run rigid-body --steps 10 --every 1 --format npy --out "$out/full" >/dev/null
cp "$out/full/rigid-body.csv" "$out/old.csv"
rc=0; limited run rigid-body --steps 5000 --every 1 --format npy --out "$out/full" >/dev/null 2>"$out/stderr" || rc=$?
[ "$rc" -eq 1 ] && grep -q "rigid-body.csv.*File too large" "$out/stderr" ||
    { cat "$out/stderr"; fail "a CSV too large to write: exit status $rc"; }
cmp -s "$out/old.csv" "$out/full/rigid-body.csv" || fail "a CSV that could not be written lost the old one"
no_temporaries "$out/full"
# The same with SIGXFSZ at its default action, which ends a process writing
# past the limit (exit 153, no message, the temporary file left): lpi's files
# and its standard output fail as above instead.
rc=0; (trap - XFSZ; ulimit -f 40; exec "$lpi" run rigid-body --steps 5000 --every 1 --format npy --out "$out/full") \
    >/dev/null 2>"$out/stderr" || rc=$?
[ "$rc" -eq 1 ] && grep -q "rigid-body.csv.*File too large" "$out/stderr" ||
    { cat "$out/stderr"; fail "a CSV past the file-size limit, SIGXFSZ not ignored: exit status $rc, expected 1"; }
cmp -s "$out/old.csv" "$out/full/rigid-body.csv" || fail "a CSV past the file-size limit lost the old one"
no_temporaries "$out/full"
rc=0; (trap - XFSZ; ulimit -f 1; exec "$lpi" methods) >"$out/methods.txt" 2>"$out/stderr" || rc=$?
[ "$rc" -eq 1 ] && grep -q "standard output.*File too large" "$out/stderr" ||
    { cat "$out/stderr"; fail "standard output past the file-size limit: exit status $rc, expected 1"; }
if [ "$have_se" = 1 ]; then
    # The .npy files are replaced as one set: the last one failing keeps them all.
    set -- run sine-euler --N 31 --every 1 --snapshots 1 --format npy --out "$out/set"
    "$lpi" "$@" --steps 4 >/dev/null
    (cd "$out/set/sine-euler" && md5sum -- * > "$out/set.md5")
    rc=0; limited "$@" --steps 6 >/dev/null 2>"$out/stderr" || rc=$?
    [ "$rc" -eq 1 ] && grep -q "vorticity.npy.*File too large" "$out/stderr" ||
        { cat "$out/stderr"; fail "a .npy set too large to write: exit status $rc"; }
    (cd "$out/set/sine-euler" && md5sum -c --quiet "$out/set.md5") || fail "a failed .npy set mixed new files with old"
    no_temporaries "$out/set/sine-euler"
    # HDF5 data that cannot be written fails as any file does (HDF5 writing
    # the file itself crashed at exit then: status 139).
    if "$lpi" run rigid-body --steps 1 --format h5 --out "$out/probe" >/dev/null 2>&1; then
        set -- run sine-euler --N 31 --every 1 --snapshots 1 --format h5 --out "$out/h5set"
        "$lpi" "$@" --steps 4 >/dev/null
        cp "$out/h5set/sine-euler.h5" "$out/old.h5"
        rc=0; limited "$@" --steps 10 >/dev/null 2>"$out/stderr" || rc=$?
        [ "$rc" -eq 1 ] && grep -q "sine-euler.h5.*File too large" "$out/stderr" ||
            { cat "$out/stderr"; fail "HDF5 data too large to write: exit status $rc, expected 1"; }
        cmp -s "$out/old.h5" "$out/h5set/sine-euler.h5" || fail "HDF5 data that could not be written lost the old file"
        no_temporaries "$out/h5set"
    fi
fi
# A CSV that cannot be written with a checkpoint stops the run (it went on,
# the checkpoint ahead of the CSV), and the CSV reaches the checkpoint left:
# resumed, the run's CSV is the uninterrupted run's (no new file started at
# the checkpoint's step, the rows before it and the energy at step 0 lost).
# (A CSV of 8 KiB, some 80 rows: every row a checkpoint, each with its
# fsyncs, and 400 rows took this test 10 s.)
set -- run rigid-body --steps 200 --every 1 --format npy
"$lpi" "$@" --out "$out/ck-whole" >/dev/null
set -- "$@" --checkpoint "$out/ck-full.lpi" --checkpoint-every 1
rc=0; (trap '' XFSZ; ulimit -f 8; exec "$lpi" "$@" --out "$out/ck-full") >"$out/stdout" 2>"$out/stderr" || rc=$?
[ "$rc" -eq 1 ] && grep -q "rigid-body.csv.*File too large" "$out/stderr" && ! grep -q "^done" "$out/stdout" ||
    { cat "$out/stderr"; fail "a CSV that cannot be written with its checkpoint: exit status $rc, expected 1 at once"; }
"$lpi" "$@" --out "$out/ck-full" --resume "$out/ck-full.lpi" >"$out/stdout"
! grep -q "a new file" "$out/stdout" || { cat "$out/stdout"; fail "the CSV left does not reach the checkpoint"; }
cmp -s "$out/ck-whole/rigid-body.csv" "$out/ck-full/rigid-body.csv" ||
    fail "a run stopped by a CSV it could not write, resumed: not the uninterrupted run's CSV"
# Its data too: the stopped run wrote it (it exited without, and the
# snapshots before the checkpoint, in memory alone, were lost).
diff -r "$out/ck-whole/rigid-body" "$out/ck-full/rigid-body" >/dev/null ||
    fail "a run stopped by a CSV it could not write, resumed: not the uninterrupted run's data"
# A checkpoint save that fails after the first stops the run (exit status 1)
# with its data written: the snapshots since the start (or the checkpoint
# resumed from) were in memory alone, and were lost. The checkpoint's
# directory is moved away once the first save is there (a checkpoint does
# not grow, so ulimit -f cannot fail a later save alone; root writes
# through a mode). Resumed, the run is the uninterrupted one, data included.
rm -rf "$out/ck-dir" "$out/ck-dir.gone" "$out/ck-gone" "$out/ck-ref"; mkdir -p "$out/ck-dir"
set -- run rigid-body --dt 0.01 --every 100000 --snapshots 1 --format npy
timeout 60 "$lpi" "$@" --steps 1000000000 --out "$out/ck-gone" --checkpoint "$out/ck-dir/run.lpi" \
    --checkpoint-every 1 >"$out/stdout" 2>"$out/stderr" &
pid=$!
waited=0
until [ -f "$out/ck-dir/run.lpi" ] || [ $waited -ge 600 ]; do sleep 0.05; waited=$((waited + 1)); done
mv "$out/ck-dir" "$out/ck-dir.gone"
rc=0; wait $pid || rc=$?
[ "$rc" -eq 1 ] && grep -q "checkpoint not written at step" "$out/stderr" ||
    { cat "$out/stderr"; fail "a checkpoint save that failed mid-run: exit status $rc, expected 1"; }
[ -f "$out/ck-gone/rigid-body/state.npy" ] || fail "a checkpoint save that failed mid-run: no data written"
stop=$(tail -n 1 "$out/ck-gone/rigid-body.csv" | cut -d, -f1)
mv "$out/ck-dir.gone" "$out/ck-dir"
"$lpi" "$@" --steps $((stop + 300000)) --out "$out/ck-gone" --checkpoint "$out/ck-dir/run.lpi" \
    --checkpoint-every 1 --resume "$out/ck-dir/run.lpi" >/dev/null
"$lpi" "$@" --steps $((stop + 300000)) --out "$out/ck-ref" >/dev/null
cmp -s "$out/ck-ref/rigid-body.csv" "$out/ck-gone/rigid-body.csv" &&
    diff -r "$out/ck-ref/rigid-body" "$out/ck-gone/rigid-body" >/dev/null ||
    fail "a run stopped by a failed checkpoint save, resumed: not the uninterrupted run"
# A CSV that cannot be written at the end does not keep the data from being
# written (it was not tried): the data, where the snapshots are, fits.
rc=0; limited run rigid-body --steps 1000 --every 1 --format npy --out "$out/csv-only" >/dev/null 2>"$out/stderr" ||
    rc=$?
[ "$rc" -eq 1 ] && grep -q "rigid-body.csv.*File too large" "$out/stderr" ||
    { cat "$out/stderr"; fail "a CSV too large to write at the end: exit status $rc, expected 1"; }
head -c 128 "$out/csv-only/rigid-body/step.npy" 2>/dev/null | grep -q "'shape': (1001,)" ||
    fail "a CSV too large to write at the end: the data was not written"
# Modes: a replaced file keeps its own, a new one gets the umask's; a FIFO
# at an output is refused before the work, and stays a FIFO.
formats=npy
"$lpi" run rigid-body --steps 1 --format h5 --out "$out/probe" >/dev/null 2>&1 && formats="npy h5"
for format in $formats; do
    data=rigid-body.h5; [ "$format" = h5 ] || data=rigid-body/state.npy
    rm -rf "$out/mode"
    (umask 022; "$lpi" run rigid-body --steps 2 --format $format --out "$out/mode" >/dev/null)
    [ "$(stat -c %a "$out/mode/$data")" = 644 ] || fail "a new $data has mode $(stat -c %a "$out/mode/$data"), not 644"
    chmod 640 "$out/mode/$data" "$out/mode/rigid-body.csv"
    (umask 022; "$lpi" run rigid-body --steps 2 --format $format --out "$out/mode" >/dev/null)
    for f in "$data" rigid-body.csv; do
        [ "$(stat -c %a "$out/mode/$f")" = 640 ] || fail "a replaced $f has mode $(stat -c %a "$out/mode/$f"), not 640"
    done
    rm -f "$out/mode/$data"
    if mkfifo "$out/mode/$data" 2>/dev/null; then
        expect 1 "$data.*not a regular file" run rigid-body --steps 2 --format $format --out "$out/mode"
        [ -p "$out/mode/$data" ] || fail "a FIFO at $data was replaced"
    fi
done

# A run killed outright (SIGKILL: nothing it can catch or write) leaves the
# CSV and the data written with its last checkpoint: resumed, it is the
# uninterrupted run, its snapshots from the start included (the data was
# written only when the run ended, and a killed run's snapshots were lost).
for format in $formats; do
    rm -rf "$out/killed" "$out/killed-ref" "$out/killed.lpi"
    set -- run rigid-body --dt 0.01 --every 100000 --snapshots 1 --format $format
    "$lpi" "$@" --steps 1000000000 --out "$out/killed" --checkpoint "$out/killed.lpi" \
        --checkpoint-every 1 >/dev/null 2>&1 &
    pid=$!  # lpi's own (SIGKILL to a wrapper such as timeout would leave lpi running)
    rows_at_least() {
        waited=0
        until [ "$(cat "$out/killed/rigid-body.csv" 2>/dev/null | wc -l)" -ge "$1" ] || [ $waited -ge 600 ]; do
            sleep 0.05; waited=$((waited + 1))
        done
    }
    # The files a checkpoint writes grow in place (a whole rewrite at each
    # checkpoint made n rows cost n^2): a hard link taken early names the
    # same file, grown, at the end.
    rows_at_least 3
    grown="$out/killed/rigid-body.csv"; [ "$format" = h5 ] || grown="$grown $out/killed/rigid-body/state.npy"
    for f in $grown; do ln -f "$f" "$f.early"; done
    rows_at_least 6
    kill -KILL $pid 2>/dev/null || true
    wait $pid 2>/dev/null || true
    for f in $grown; do
        [ "$f" -ef "$f.early" ] || fail "SIGKILL ($format): $f was replaced at a checkpoint, not grown in place"
        rm -f "$f.early"
    done
    # The last whole line (the kill may have cut the one after it).
    rows=$(wc -l <"$out/killed/rigid-body.csv")
    stop=$(head -n "$rows" "$out/killed/rigid-body.csv" | tail -n 1 | cut -d, -f1)
    [ "$stop" -ge 400000 ] || fail "SIGKILL: the run was not killed mid-run (last row at step $stop)"
    # A kill within a growth leaves bytes past what the files account for (a
    # line cut short, values past an array's header): resumed, they go.
    printf '%s' "$((stop + 100000)),4" >>"$out/killed/rigid-body.csv"
    for f in "$out/killed/rigid-body/"*.npy "$out/killed/rigid-body.h5-pending/"*.npy; do
        [ ! -f "$f" ] || printf 'cut' >>"$f"
    done
    "$lpi" "$@" --steps $((stop + 300000)) --out "$out/killed" --checkpoint "$out/killed.lpi" \
        --checkpoint-every 1 --resume "$out/killed.lpi" >"$out/stdout"
    ! grep -q "no data there" "$out/stdout" || { cat "$out/stdout"; fail "SIGKILL ($format): no data left"; }
    "$lpi" "$@" --steps $((stop + 300000)) --out "$out/killed-ref" >/dev/null
    # The kill may land in a write, whose temporary file it leaves behind.
    data=rigid-body.h5; [ "$format" = h5 ] || data=rigid-body
    cmp -s "$out/killed-ref/rigid-body.csv" "$out/killed/rigid-body.csv" &&
        diff -r -x '.lpi-*' "$out/killed-ref/$data" "$out/killed/$data" >/dev/null ||
        fail "a run killed by SIGKILL ($format), resumed: not the uninterrupted run"
done

# Killed before its second checkpoint, a run resumes from the one at its
# start, whose data holds the start's snapshot (taken after that checkpoint,
# it was in no file, and the resumed run never took it).
rm -rf "$out/early" "$out/early-ref" "$out/early.lpi"
set -- run rigid-body --dt 0.01 --every 100000 --snapshots 1 --format npy
"$lpi" "$@" --steps 1000000000 --out "$out/early" --checkpoint "$out/early.lpi" --checkpoint-every 0 \
    >/dev/null 2>&1 &
pid=$!
waited=0
until [ -f "$out/early.lpi" ] || [ $waited -ge 600 ]; do sleep 0.05; waited=$((waited + 1)); done
sleep 0.2
kill -KILL $pid 2>/dev/null || true
wait $pid 2>/dev/null || true
"$lpi" "$@" --steps 300000 --out "$out/early" --resume "$out/early.lpi" >"$out/stdout"
"$lpi" "$@" --steps 300000 --out "$out/early-ref" >/dev/null
cmp -s "$out/early-ref/rigid-body.csv" "$out/early/rigid-body.csv" &&
    diff -r -x '.lpi-*' "$out/early-ref/rigid-body" "$out/early/rigid-body" >/dev/null ||
    { cat "$out/stdout"; fail "a run killed after its first checkpoint, resumed: not the uninterrupted run"; }

# A kill between two renames of the .npy set leaves files of two writes in
# turn, which share the rows and snapshots up to the checkpoint: resumed,
# the run reads those and ends as the uninterrupted run (such a set was
# refused as damaged, its arrays differing in length, and its snapshots
# could be kept only by hand).
rm -rf "$out/mixed" "$out/mixed-old" "$out/mixed-ref" "$out/mixed.lpi" "$out/mixed-later.lpi"
set -- run rigid-body --every 5 --snapshots 1 --format npy
"$lpi" "$@" --steps 30 --out "$out/mixed-ref" >/dev/null
"$lpi" "$@" --steps 10 --out "$out/mixed" --checkpoint "$out/mixed.lpi" >/dev/null
cp -r "$out/mixed/rigid-body" "$out/mixed-old"
"$lpi" "$@" --steps 20 --out "$out/mixed" --checkpoint "$out/mixed-later.lpi" --resume "$out/mixed.lpi" >/dev/null
for name in time energy snapshot_time; do cp "$out/mixed-old/$name.npy" "$out/mixed/rigid-body/"; done
"$lpi" "$@" --steps 30 --out "$out/mixed" --resume "$out/mixed.lpi" >"$out/stdout" 2>"$out/stderr" ||
    { cat "$out/stderr"; fail "a .npy set of two writes, resumed: refused"; }
! grep -q "keeps the snapshots from" "$out/stdout" || { cat "$out/stdout"; fail "a .npy set of two writes: dropped"; }
cmp -s "$out/mixed-ref/rigid-body.csv" "$out/mixed/rigid-body.csv" &&
    diff -r "$out/mixed-ref/rigid-body" "$out/mixed/rigid-body" >/dev/null ||
    fail "a .npy set of two writes, resumed: not the uninterrupted run"

# Data moved aside (as a refusal asks) or older than the checkpoint,
# resumed: the data goes on from the checkpoint's step with the snapshot at
# that step, taken from the resumed state (the uninterrupted run's, to the
# bit; the run took none there, and the data said it kept the snapshots
# "from" that step), and where the kept snapshots end before the grid's
# last one before the checkpoint, the run says which it lacks.
npy_words() {  # npy_words FILE: its values after the header, one 8-byte word a line, in hex
    header=$(head -c 10 "$1" | tail -c 2 | od -An -tu2 --endian=little | tr -d ' ')
    tail -c +$((header + 11)) "$1" | od -An -v -tx8 -w8
}
rm -rf "$out/aside" "$out/aside-ref" "$out/aside-old" "$out/aside.lpi" "$out/aside-later.lpi"
set -- run rigid-body --every 5 --snapshots 1 --format npy
"$lpi" "$@" --steps 30 --out "$out/aside-ref" >/dev/null
ref="$out/aside-ref/rigid-body"
"$lpi" "$@" --steps 20 --out "$out/aside" --checkpoint "$out/aside.lpi" >/dev/null
mv "$out/aside/rigid-body" "$out/aside-old"
"$lpi" "$@" --steps 30 --out "$out/aside" --resume "$out/aside.lpi" >"$out/stdout"
grep -q "no data there; the data keeps the snapshots from step 20 on" "$out/stdout" || { cat "$out/stdout"; fail "data moved aside, resumed: no note"; }
[ "$(npy_words "$out/aside/rigid-body/snapshot_step.npy")" = "$(npy_words "$ref/snapshot_step.npy" | tail -n 3)" ] &&
    [ "$(npy_words "$out/aside/rigid-body/state.npy")" = "$(npy_words "$ref/state.npy" | tail -n 9)" ] ||
    fail "data moved aside, resumed: not the snapshots from the checkpoint's step (step 20's missing) as the uninterrupted run's"
rm -rf "$out/aside" "$out/aside-old"
"$lpi" "$@" --steps 10 --out "$out/aside" --checkpoint "$out/aside.lpi" >/dev/null
cp -r "$out/aside/rigid-body" "$out/aside-old"
"$lpi" "$@" --steps 20 --out "$out/aside" --checkpoint "$out/aside-later.lpi" --resume "$out/aside.lpi" >/dev/null
rm -rf "$out/aside/rigid-body"; mv "$out/aside-old" "$out/aside/rigid-body"
"$lpi" "$@" --steps 30 --out "$out/aside" --resume "$out/aside-later.lpi" >"$out/stdout"
grep -q "its snapshots end at step 10: those after it and before step 20 are not in it" "$out/stdout" ||
    { cat "$out/stdout"; fail "data older than the checkpoint, resumed: no note of the snapshots it lacks"; }
[ "$(npy_words "$out/aside/rigid-body/snapshot_step.npy")" = "$(npy_words "$ref/snapshot_step.npy" | sed 4d)" ] &&
    [ "$(npy_words "$out/aside/rigid-body/state.npy")" = "$(npy_words "$ref/state.npy" | sed 10,12d)" ] &&
    cmp -s "$ref/../rigid-body.csv" "$out/aside/rigid-body.csv" ||
    fail "data older than the checkpoint, resumed: not its snapshots, the checkpoint step's and later ones as the uninterrupted run's"

# Data that cannot be written with a checkpoint (its snapshots past the
# file size limit, the CSV still within it) stops the run as a CSV does,
# leaving the data of the last checkpoint: resumed, the run is the
# uninterrupted one.
# With HDF5 the file is the one that grows past the limit (its journal of
# the snapshots since its last whole write holds at most as many): resumed
# from the file and its journal, the run is the uninterrupted one.
if [ "$have_se" = 1 ]; then
    for format in $formats; do
        rm -rf "$out/dck" "$out/dck-ref" "$out/dck.lpi"
        set -- run sine-euler --N 15 --every 1 --snapshots 1 --steps 24 --format $format
        "$lpi" "$@" --out "$out/dck-ref" >/dev/null
        rc=0; limited "$@" --out "$out/dck" --checkpoint "$out/dck.lpi" --checkpoint-every 1 \
            >"$out/stdout" 2>"$out/stderr" || rc=$?
        data=sine-euler.h5; grown=sine-euler.h5; [ "$format" = h5 ] || data=sine-euler grown=vorticity.npy
        [ "$rc" -eq 1 ] && grep -q "$grown.*File too large" "$out/stderr" && ! grep -q "^done" "$out/stdout" ||
            { cat "$out/stderr"; fail "data that cannot be written with a checkpoint ($format): exit status $rc, expected 1 at once"; }
        for dir in "$out/dck" "$out/dck/sine-euler" "$out/dck/sine-euler.h5-pending"; do
            [ ! -d "$dir" ] || no_temporaries "$dir"
        done
        if [ "$format" = h5 ]; then
            journal="$out/dck/sine-euler.h5-pending"
            [ -f "$journal/vorticity.npy" ] ||
                fail "HDF5 data that cannot be written whole: no journal of the snapshots since left"
            # A journal whose base cannot be read is refused, not ignored (the
            # rows and snapshots it holds would be lost), and nothing is written.
            cp "$journal/base.npy" "$out/base.npy"
            printf 'x' >"$journal/base.npy"
            cp "$out/dck/sine-euler.h5" "$out/dck.h5"
            rc=0; "$lpi" "$@" --out "$out/dck" --checkpoint "$out/dck.lpi" --checkpoint-every 1 \
                --resume "$out/dck.lpi" >"$out/stdout" 2>"$out/stderr" || rc=$?
            [ "$rc" -eq 1 ] && grep -q "base.npy" "$out/stderr" && cmp -s "$out/dck.h5" "$out/dck/sine-euler.h5" ||
                { cat "$out/stderr"; fail "an HDF5 journal whose base cannot be read: exit status $rc, expected 1, the data kept"; }
            cp "$out/base.npy" "$journal/base.npy"
        fi
        "$lpi" "$@" --out "$out/dck" --checkpoint "$out/dck.lpi" --checkpoint-every 1 --resume "$out/dck.lpi" \
            >"$out/stdout"
        ! grep -q "no data there" "$out/stdout" || { cat "$out/stdout"; fail "data stopped at a checkpoint: none left"; }
        [ ! -e "$out/dck/sine-euler.h5-pending" ] || fail "a run ended with its HDF5 journal left"
        cmp -s "$out/dck-ref/sine-euler.csv" "$out/dck/sine-euler.csv" &&
            diff -r "$out/dck-ref/$data" "$out/dck/$data" >/dev/null ||
            fail "a run stopped by data it could not write ($format), resumed: not the uninterrupted run"
    done
fi

# --checkpoint: refused up front when it cannot work or would overwrite an
# output, and a failed first save leaves the old CSV.
"$lpi" run moments --steps 3 --out "$out/ck" >/dev/null
"$lpi" run rigid-body --steps 3 --out "$out/ck" >/dev/null
cp "$out/ck/moments.csv" "$out/moments.csv"; cp "$out/ck/rigid-body.csv" "$out/rigid.csv"
expect 2 "moments cannot be checkpointed" run moments --steps 3 --out "$out/ck" --checkpoint "$out/m.lpi"
expect 2 "moments cannot be checkpointed" run moments --steps 3 --out "$out/ck" --resume "$out/m.lpi"
expect 1 "no-such-dir" run rigid-body --steps 9 --out "$out/ck" --checkpoint "$out/no-such-dir/x.lpi"
mkdir -p "$out/a-dir.lpi"
expect 1 "a-dir.lpi.*directory" run rigid-body --steps 9 --out "$out/ck" --checkpoint "$out/a-dir.lpi"
expect 2 "--checkpoint.*which this run writes" run rigid-body --steps 9 --out "$out/ck" --checkpoint "$out/ck/rigid-body.csv"
expect 2 "--checkpoint.*which this run writes" run rigid-body --steps 9 --out "$out/ck" --checkpoint "$out/ck//./rigid-body.csv"
expect 2 "--checkpoint.*which this run writes" run rigid-body --steps 9 --out "$out/ck" --format npy \
    --checkpoint "$out/ck/rigid-body/state.npy"
# An --out that does not exist yet, spelt with "//", "/./" or "x/..": the
# same file all the same (it had silently replaced the CSV with the checkpoint).
expect 2 "--checkpoint.*which this run writes" run rigid-body --steps 9 --out "$out/new1/" \
    --checkpoint "$out/new1/rigid-body.csv"
expect 2 "--checkpoint.*which this run writes" run rigid-body --steps 9 --out "$out/new2" \
    --checkpoint "$out/new2/./x/../rigid-body.csv"
expect 2 "--checkpoint.*is in .*the folder where this run writes its data" run rigid-body --steps 9 \
    --out "$out/new3//" --format npy --checkpoint "$out/new3/rigid-body/x.lpi"
"$lpi" run rigid-body --steps 9 --out "$out/new4/" --checkpoint "$out/new4/rigid-body.h5-pending2" >/dev/null ||
    fail "a --checkpoint whose name only begins with the journal's was refused"
# The folders the data is written in: the .npy folder, the HDF5 file's journal.
expect 2 "--checkpoint.*is in .*the folder where this run writes its data" run rigid-body --steps 9 \
    --out "$out/ck" --format npy --checkpoint "$out/ck/rigid-body/x.lpi"
expect 2 "--checkpoint.*is .*the folder where this run writes its data" run rigid-body --steps 9 \
    --out "$out/ck" --format npy --checkpoint "$out/ck/rigid-body"
case $formats in *h5*)
    expect 2 "--checkpoint.*which this run writes" run rigid-body --steps 9 --out "$out/ck" --format h5 \
        --checkpoint "$out/ck/rigid-body.h5"
    expect 2 "--checkpoint.*the folder where this run writes its data" run rigid-body --steps 9 --out "$out/ck" \
        --format h5 --checkpoint "$out/ck/rigid-body.h5-pending"
    expect 2 "--checkpoint.*is in .*the folder where this run writes its data" run rigid-body --steps 9 \
        --out "$out/ck" --format h5 --checkpoint "$out/ck/rigid-body.h5-pending/step.npy" ;;
esac
cmp -s "$out/moments.csv" "$out/ck/moments.csv" || fail "a refused --checkpoint changed moments.csv"
cmp -s "$out/rigid.csv" "$out/ck/rigid-body.csv" || fail "a failed --checkpoint changed rigid-body.csv"
# --resume with another --dt: the checkpoint's time at step 10 of 0.1 is
# step 20 of 0.05 (as the CSV says, or the data, which records the --dt).
"$lpi" run rigid-body --dt 0.05 --steps 20 --out "$out/dt" --checkpoint "$out/dt.lpi" >/dev/null
expect 2 "--dt 0.1, but the interrupted run's is 0.05" run rigid-body --dt 0.1 --steps 30 --out "$out/dt" \
    --resume "$out/dt.lpi"
for data in "$out/dt/rigid-body.h5" "$out/dt/rigid-body"; do
    [ ! -e "$data" ] || { mv "$data" "$out/dt-data"; kept_data=$data; }
done
expect 2 "resume with the options of the interrupted run" run rigid-body --dt 0.1 --steps 30 --out "$out/dt" \
    --resume "$out/dt.lpi"
mv "$out/dt-data" "$kept_data"
rm "$out/dt/rigid-body.csv"
expect 2 "--dt 0.1, but the interrupted run's is 0.05" run rigid-body --dt 0.1 --steps 30 --out "$out/dt" \
    --resume "$out/dt.lpi"
# A row removed from the CSV (no data beside it): the rows' own layout is
# refused, and so is an --every other than the interrupted run's.
"$lpi" run rigid-body --steps 200 --out "$out/gap" --checkpoint "$out/gap.lpi" >/dev/null
rm -rf "$out/gap/rigid-body.h5" "$out/gap/rigid-body"
cp "$out/gap/rigid-body.csv" "$out/gap.csv"
expect 2 "--every 3, but the interrupted run's is 2" run rigid-body --steps 400 --every 3 --out "$out/gap" \
    --resume "$out/gap.lpi"
sed -i 5d "$out/gap/rigid-body.csv"
expect 2 "rows are not every 4 steps (the largest step between the rows of .*row 1 is at step 2, not 4" \
    run rigid-body --steps 400 --out "$out/gap" --resume "$out/gap.lpi"
# --init: a FIFO is refused, not waited on.
rm -f "$out/fifo.npy"
if mkfifo "$out/fifo.npy" 2>/dev/null; then
    expect 1 "not a regular file" run sine-euler --init "$out/fifo.npy" --steps 1 --out "$out/init"
fi

if [ "$have_se" = 1 ]; then
    # H(0) = 0: the absolute energy error, named so in the CSV.
    "$lpi" run qg --N 9 --kd 1e200 --steps 3 --out "$out/zero" >"$out/stdout" || fail "lpi run qg --kd 1e200"
    ! grep -qi nan "$out/stdout" "$out/zero/qg.csv" || { cat "$out/stdout"; fail "H(0) = 0: a NaN energy error"; }
    head -n 1 "$out/zero/qg.csv" | grep -q "^step,time,energy,absolute_energy_error," ||
        fail "H(0) = 0: the CSV does not say the error is absolute"
    # rollup stops on SIGINT and SIGTERM as lpi run does, its CSV written.
    for signal in INT TERM; do
        rm -rf "$out/roll"
        "$lpi" run rollup --N 9 --steps 1000000000 --out "$out/roll" >"$out/roll.out" 2>&1 &
        pid=$!
        waited=0
        # Its signal handler is in place once it says it is stepping.
        until grep -q "stepping" "$out/roll.out" || [ $waited -ge 300 ]; do sleep 0.1; waited=$((waited + 1)); done
        sleep 0.3
        kill -$signal $pid
        rc=0; wait $pid || rc=$?
        want=130; [ $signal = TERM ] && want=143
        [ "$rc" -eq $want ] && grep -q "interrupted at step" "$out/roll.out" ||
            { cat "$out/roll.out"; fail "rollup, SIG$signal: exit status $rc, expected $want"; }
        [ "$(wc -l < "$out/roll/rollup.csv")" -ge 2 ] && [ -s "$out/roll/rollup_spectra.csv" ] ||
            fail "rollup, SIG$signal: the CSV files were not written"
        [ "$(tail -n 1 "$out/roll/rollup.csv" | tr -cd , | wc -c)" -eq 3 ] || fail "rollup, SIG$signal: last row cut"
    done
fi
echo "PASS: lpi's files: no shell, failed plots and writes reported, old files kept, paths checked"
