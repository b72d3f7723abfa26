#!/bin/sh
# check_lpi_report.sh LPI OUTDIR SCENE [OPTION...]
# Runs `lpi report SCENE` and checks, from its exit status and its CSV files,
# the property that scene exists to show. Exits 77 when the build cannot run
# the scene (no FFTW or no LAPACK), 1 on any failed check.
set -u
lpi=$1 out=$2 scene=$3
shift 3
rm -rf "$out"
log=$out.log
"$lpi" report "$scene" --out "$out" "$@" >"$log" 2>&1
status=$?
cat "$log"
if grep -q "== $scene: skipped in this build" "$log"; then
    echo "SKIP: $scene cannot run in this build"
    exit 77
fi
if [ "$status" -ne 0 ]; then
    echo "FAIL: lpi report $scene exited with status $status"
    exit 1
fi
fail() {
    echo "FAIL: $*"
    exit 1
}

case $scene in
rigid-body | pendulum | moments | sine-euler)
    # The work-precision scenes of the default report (`make run`).
    # SCENE.csv: scene,method,order,dt,steps,cpu_seconds,error,
    # max_energy_error,max_casimir_drift,status; rows by method, largest dt first.
    csv=$out/$scene.csv
    [ -s "$csv" ] || fail "no $csv"
    # A reference must resolve what the table measures (the pendulum's rk4
    # reference was off by 8e-12, more than the errors of the 8th-order
    # methods it judged): the errors it does not resolve are stated, below
    # 1e-12, and the rows within them marked ~ref, and only those.
    unresolved=$(sed -n 's/.*errors below \([^ ]*\) are not resolved by the reference.*/\1/p' "$log")
    [ -n "$unresolved" ] || fail "what the reference does not resolve is not stated"
    awk -v u="$unresolved" 'BEGIN { exit !(u + 0 > 0 && u + 0 < 1e-12) }' ||
        fail "the reference leaves errors below $unresolved unresolved: it resolves no small error"
    if [ "$scene" != rigid-body ]; then
        # Its round-off too, which its run at twice the step shares: its
        # difference from another method at its step is stated.
        grep -q "from its run at twice the step and by [^ ]* from" "$log" ||
            fail "the reference's difference from another method is not stated"
    fi
    awk -v u="$unresolved" '$1 ~ /^[a-z]/ && $3 ~ /^[0-9]+$/ && $5 ~ /e[-+]/ {
        marked = ($NF == "~ref"); small = ($5 + 0 <= u + 0)
        if (marked != small) { print "FAIL: " $1 " at dt " $2 ": error " $5 (marked ? " marked" : " not marked") " ~ref"; bad = 1 }
    } END { exit bad }' "$log" || exit 1
    # Round-off of the Casimirs for the splitting methods (the moments' I and
    # K are quartic in the state: 1.3e-13 seen for yoshida-8).
    casimir_limit=1e-13
    [ "$scene" = moments ] && casimir_limit=1e-12
    awk -F, -v limit="$casimir_limit" '
        NR == 1 { next }
        $10 != "LPI_OK" { print "FAIL: " $2 " at dt " ($4 + 0) ": " $10; bad = 1 }
        # The splitting methods keep every Casimir to round-off; the baselines
        # (isomp only to its iteration tolerance) are not held to it.
        $2 !~ /^(rk4|rk4-matrix|implicit-midpoint|isomp|direct-eq5)$/ && !($9 < limit + 0) {
            print "FAIL: " $2 " at dt " ($4 + 0) " changed a Casimir by " $9; bad = 1 }
        # rk4 does not: at its largest step the drift is far above round-off.
        $2 == "rk4" && !seen_rk4++ && !($9 > 1e-8) {
            print "FAIL: rk4 at dt " ($4 + 0) " kept the Casimirs to " $9 " (the column measures nothing?)"; bad = 1 }
        # Leapfrog is second order: the last two halvings of dt divide the error by 4.
        $2 == "leapfrog" { previous = last; last = $7 }
        # A sweep starts past 1e-2, or at one step over T: a time to 1e-2
        # read off a largest step far below it was only a bound, and named
        # a slower method the best.
        $2 != method { method = $2
            if ($10 == "LPI_OK" && $7 + 0 < 1e-2 && $5 + 0 > 1) {
                print "FAIL: " $2 ": its largest step (dt " ($4 + 0) ") already has error " $7 " < 1e-2"; bad = 1 } }
        END {
            if (!seen_rk4) { print "FAIL: no rk4 row"; bad = 1 }
            if (!(last > 0 && previous > 0)) { print "FAIL: no leapfrog sweep"; exit 1 }
            order = log(previous / last) / log(2)
            printf "leapfrog: measured order %.3f\n", order
            if (order < 1.9 || order > 2.1) { print "FAIL: leapfrog order " order; bad = 1 }
            exit bad
        }' "$csv" || exit 1
    ;;
figure2)
    grep -q "bounded, no secular growth" "$log" || fail "the energy error grows"
    # figure2.csv: time,energy_error,c2_drift,spectrum_drift, every 100 steps.
    awk -F, '
        NR == 1 { next }
        { e = $2 < 0 ? -$2 : $2; if (e > worst) worst = e; c2 = $3 }
        END {
            printf "max |dH/H| %.3e, C2 drift after 1e5 steps %.3e\n", worst, c2
            # The paper: about 5e-5 and 5e-15 per step.
            if (!(worst > 0 && worst < 1e-4)) { print "FAIL: energy error " worst; exit 1 }
            if (!(c2 < 5e-10)) { print "FAIL: C2 drift " c2; exit 1 }
        }' "$out/figure2.csv" || exit 1
    ;;
sine-euler-long)
    # sine-euler-long.csv: scene,run,method,order,poisson,dt,steps,cpu_seconds,
    # max_energy_error,max_casimir_drift,final_casimir_drift,reached_time,status;
    # _history.csv: run,method,dt,time,energy_error,casimir_drift.
    csv=$out/sine-euler-long.csv
    [ -s "$csv" ] || fail "no $csv"
    awk -F, '
        FNR == 1 { next }
        FILENAME ~ /_history.csv$/ { n[$1]++; t[$1, n[$1]] = $4; e[$1, n[$1]] = $5; c[$1, n[$1]] = $6; next }
        { method[$2] = $3; poisson[$2] = $5; dt[$2] = $6; status[$2] = $13 }
        END {
            for (r in method) {
                name = method[r] " dt " (dt[r] + 0)
                # A baseline may fail (it says so in its row); a splitting may not.
                if (status[r] != "LPI_OK") {
                    print (poisson[r] == 1 ? "FAIL: " : "note: ") name ": " status[r]
                    if (poisson[r] == 1) bad = 1
                    continue
                }
                last = n[r]; half = int(last / 2)
                if (last < 8) { print "FAIL: " name ": " last " samples"; bad = 1; continue }
                if (poisson[r] == 1) {
                    ++splittings
                    # The splitting keeps every Casimir to round-off ...
                    for (k = 1; k <= last; ++k)
                        if (!(c[r, k] < 1e-12)) {
                            print "FAIL: " name ": Casimir drift " c[r, k] " at t = " t[r, k]; bad = 1; break }
                    # ... and its energy error stays bounded: small everywhere,
                    # and for leapfrog (whose error is smooth enough to
                    # compare) no larger over the second half than twice the
                    # first. Higher orders at large steps fluctuate more.
                    first = 0; second = 0
                    for (k = 1; k <= last; ++k)
                        if (k <= half) { if (e[r, k] > first) first = e[r, k] }
                        else if (e[r, k] > second) second = e[r, k]
                    printf "%s: max |dH/H| %.3e then %.3e, max Casimir drift below 1e-12\n", name, first, second
                    if (!(first < 0.1 && second < 0.1) || method[r] == "leapfrog" && !(second <= 2 * first)) {
                        print "FAIL: " name ": the energy error grows"; bad = 1 }
                }
                if (method[r] == "rk4-matrix") {
                    ++rk4
                    # rk4-matrix drifts secularly: far above round-off, and
                    # at the end at least ten times its drift at the first sample.
                    printf "%s: Casimir drift %.3e at t = %g, %.3e at t = %g\n", name,
                           c[r, 1], t[r, 1], c[r, last], t[r, last]
                    if (!(c[r, last] > 1e-10 && c[r, last] > 10 * c[r, 1])) {
                        print "FAIL: " name ": no secular Casimir drift"; bad = 1 }
                }
            }
            if (splittings < 3 || rk4 < 2) { print "FAIL: " splittings " splitting runs, " rk4 " rk4-matrix runs"; bad = 1 }
            exit bad
        }' "$csv" "$out/sine-euler-long_history.csv" || exit 1
    ;;
*)
    fail "no check written for scene $scene"
    ;;
esac
echo "PASS: lpi report $scene"
