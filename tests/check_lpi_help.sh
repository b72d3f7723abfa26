#!/bin/sh
# The command's help is true: every scene lpi --help lists runs (tiny sizes;
# a scene the build lacks says so), the commands it names exist, each
# subcommand's --help describes that subcommand (lpi report's the options
# it takes), the scenes and options agree with man1 (-h and help too), and
# help that cannot be written is a failure.
set -eu
lpi="$1"; out="$2"
rm -rf "$out"; mkdir -p "$out"
"$lpi" --help > "$out/help"
scenes=$(sed -n '/^scenes:/,$p' "$out/help" | sed -n 's/^  \([a-z0-9-]*\) .*/\1/p')
[ -n "$scenes" ] || { echo "lpi --help lists no scene"; exit 1; }
for scene in $scenes; do
    # The options in brackets are those the scene takes (others are refused).
    line=$(grep "^  $scene " "$out/help")
    size=; case "$line" in *"["*--N*"]"*) size="--N 5";; esac
    if grep -q "^  $scene .*(lpi report only)" "$out/help"; then
        set -- report "$scene" $size --T 5 --out "$out/$scene"
    else
        set -- run "$scene" --steps 3 $size --out "$out/$scene"
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
# The scenes and options lpi --help and each command's --help list are the
# ones man1 documents, both ways, so that neither can drift from the other.
man1="$(cd "$(dirname "$0")/.." && pwd)/man/man1/lpi.1"
# The words after the .TP tags of man1's section (.SH) or subsection (.SS) $1.
man_tags() {
    awk -v name="$1" '/^\.S[HS] / { on = (substr($0, 5) == name); next }
        on && tag { print } { tag = on && $0 == ".TP" }' "$man1" | sed 's/\\-/-/g'
}
same_list() {  # same_list WHAT HELP-LIST MAN-LIST
    if [ "$2" != "$3" ]; then
        echo "$1 differ between the help and man1 (< help, > man1):"
        printf '%s\n' "$2" >"$out/from-help"; printf '%s\n' "$3" >"$out/from-man"
        diff "$out/from-help" "$out/from-man"; exit 1
    fi
}
same_list "the scenes" "$(printf '%s\n' $scenes | sort)" \
    "$(man_tags SCENES | sed -n 's/^\.B \([a-z0-9-]*\)$/\1/p' | sort)"
for command in run report; do
    same_list "the options of lpi $command" \
        "$(sed -n 's/^  \(--[a-z][a-z-]*\).*/\1/p' "$out/$command.help" | sort -u)" \
        "$(man_tags "lpi $command" | grep -o -- '--[a-z][a-z-]*' | sort -u)"
done
# Every option the help lists is one lpi run reads (a missing value, not an
# unknown option).
for option in $(sed -n 's/^  \(--[a-z][a-z-]*\).*/\1/p' "$out/run.help"); do
    "$lpi" run rigid-body "$option" >/dev/null 2>"$out/option.err" && true
    grep -q -e "$option needs a value" "$out/option.err" ||
        { echo "lpi run --help lists $option, which lpi run does not read:"; cat "$out/option.err"; exit 1; }
done

# The options lpi report --help gives the scenes in brackets are ones lpi
# report reads (a missing value, not an unknown option); -h and help, which
# lpi takes for --help, are in man1.
for option in $(sed -n '/^scenes:/,$p' "$out/report.help" | grep -o -e '\[--[^]]*\]' | grep -o -e '--[A-Za-z][A-Za-z-]*' | sort -u); do
    "$lpi" report rigid-body "$option" >/dev/null 2>"$out/option.err" && true
    grep -q -e "$option needs a value" "$out/option.err" ||
        { echo "lpi report --help gives scenes $option, which lpi report does not read:"; cat "$out/option.err"; exit 1; }
done
"$lpi" -h | cmp -s - "$out/help" && "$lpi" help | cmp -s - "$out/help" || { echo "lpi -h or lpi help is not lpi --help"; exit 1; }
grep -q '^\.B \\-h$' "$man1" && grep -q '^\.B help$' "$man1" || { echo "man1 does not give -h and help"; exit 1; }

# A time that is 2^62 steps or more is refused (2) before anything runs:
# lpi report's --T as lpi run's --until.
rc=0; timeout 120 "$lpi" report rigid-body sine-euler-long --N 3 --T 1e300 --out "$out/long" >"$out/long.out" \
    2>"$out/long.err" || rc=$?
[ "$rc" -eq 2 ] && grep -q -e "--T: 1e+300 / .* is too many steps" "$out/long.err" && ! grep -q "^==" "$out/long.out" ||
    { echo "lpi report sine-euler-long --T 1e300: exit status $rc, expected 2 before any scene runs"; cat "$out/long.err"; exit 1; }

# A --T below the sweep's largest step (every run one step of T, the rows
# repeating one another, the plot empty) is refused (2) before anything runs.
rc=0; "$lpi" report sine-euler-long --N 3 --T 1e-20 --out "$out/short" >"$out/short.out" 2>"$out/short.err" || rc=$?
[ "$rc" -eq 2 ] && grep -q -e "which --T must reach" "$out/short.err" && ! grep -q "^==" "$out/short.out" ||
    { echo "lpi report sine-euler-long --T 1e-20: exit status $rc, expected 2"; cat "$out/short.err"; exit 1; }
# An option where a value belongs is refused (2), not taken as the value
# (--out --help wrote into ./--help).
rc=0; (cd "$out" && "$lpi" report pendulum --out --help) >"$out/value.out" 2>"$out/value.err" || rc=$?
[ "$rc" -eq 2 ] && grep -q -e "--out needs a value, not the option '--help'" "$out/value.err" && [ ! -e "$out/--help" ] ||
    { echo "lpi report --out --help: exit status $rc, expected 2"; cat "$out/value.err"; exit 1; }

# Standard output that cannot be written fails the command (exit status 1);
# an argument after --version or --help is refused (2).
if [ -w /dev/full ]; then
    for command in --version --help "run --help" methods; do
        rc=0; "$lpi" $command >/dev/full 2>"$out/full.err" || rc=$?
        [ "$rc" -eq 1 ] && grep -q "standard output" "$out/full.err" ||
            { echo "lpi $command >/dev/full: exit status $rc, expected 1 with a message"; cat "$out/full.err"; exit 1; }
    done
else
    echo "not checked: output to /dev/full (none here)"
fi
# The exit statuses lpi --help gives are those of man1 and lpi run --help.
for status in 130 143; do
    grep -q "$status" "$out/help" || { echo "lpi --help does not give exit status $status"; exit 1; }
done
# man1 as it renders: an alternating-font macro (.BR, .IR, ...) joins its
# arguments without spaces, so an argument ending in prose punctuation
# before another ran words together (".BR \-\-T ): leapfrog, mclachlan-4,").
awk '/^\.(BR|RB|BI|IB|IR|RI) / {
        line = substr($0, 5); n = 0
        while (match(line, /^ *("[^"]*"|[^ ]+)/)) {
            arg[++n] = substr(line, RSTART, RLENGTH); line = substr(line, RLENGTH + 1)
        }
        for (i = 1; i < n; ++i)
            if (arg[i] ~ /[,;:]$/) { print FILENAME ":" FNR ": words run together: " $0; bad = 1; break }
    } END { exit bad }' "$man1" || exit 1
grep -q "Steps are 64-bit integers, everything else" "$man1" &&
    { echo "man1: the integer datasets are more than the steps (/casimir, /component)"; exit 1; }
for command in --version --help; do
    rc=0; "$lpi" $command --bogus >/dev/null 2>"$out/extra.err" || rc=$?
    [ "$rc" -eq 2 ] && grep -q -e "--bogus" "$out/extra.err" ||
        { echo "lpi $command --bogus: exit status $rc, expected 2 naming --bogus"; exit 1; }
done
echo "lpi --help: every scene runs, every command exists, scenes and options as in man1"
