#!/bin/sh
# The command's help is true: every scene lpi --help lists runs (tiny sizes;
# a scene the build lacks says so), the commands it names exist, and each
# subcommand's --help describes that subcommand.
set -eu
lpi="$1"; out="$2"
rm -rf "$out"; mkdir -p "$out"
"$lpi" --help > "$out/help"
scenes=$(sed -n '/^scenes:/,$p' "$out/help" | sed -n 's/^  \([a-z0-9-]*\) .*/\1/p')
[ -n "$scenes" ] || { echo "lpi --help lists no scene"; exit 1; }
for scene in $scenes; do
    if grep -q "^  $scene .*(lpi report only)" "$out/help"; then
        set -- report "$scene" --N 5 --T 5 --out "$out/$scene"
    else
        set -- run "$scene" --steps 3 --N 5 --out "$out/$scene"
    fi
    rc=0; "$lpi" "$@" >"$out/$scene.log" 2>&1 || rc=$?
    if [ "$rc" -eq 1 ] && grep -q "not available in this build" "$out/$scene.log"; then
        echo "lpi $*: not in this build"; continue
    fi
    [ "$rc" -eq 0 ] || { echo "lpi $*: exit status $rc"; cat "$out/$scene.log"; exit 1; }
done
# Each command the usage names exists and answers --help with its own usage.
for command in report run stress methods; do
    grep -q "lpi $command" "$out/help" || { echo "lpi --help does not name lpi $command"; exit 1; }
    "$lpi" $command --help > "$out/$command.help"
    head -n 1 "$out/$command.help" | grep -q "^usage: lpi $command" ||
        { echo "lpi $command --help is not its own usage:"; head -n 3 "$out/$command.help"; exit 1; }
done
grep -q "work-precision" "$out/report.help" || { echo "lpi report --help does not describe report"; exit 1; }
# lpi methods: one row per method, the order column true for known ones.
"$lpi" methods > "$out/methods"
grep -q "^leapfrog  *2 " "$out/methods" || { echo "lpi methods: no leapfrog of order 2"; cat "$out/methods"; exit 1; }
grep -q "^yoshida-6  *6 " "$out/methods" || { echo "lpi methods: no yoshida-6 of order 6"; exit 1; }
grep -q "lpi methods" "$out/run.help" || { echo "lpi run --help does not point to lpi methods"; exit 1; }
for method in $(sed -n '2,$s/ .*//p' "$out/methods"); do
    case "$method" in isomp|rk4-matrix|direct-eq5) continue;; esac  # sine-Euler only
    "$lpi" run pendulum --method "$method" --steps 2 --out "$out/m" >/dev/null ||
        { echo "lpi methods lists $method, which lpi run refuses"; exit 1; }
done
echo "lpi --help: every scene runs, every command exists"
