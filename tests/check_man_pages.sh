#!/bin/sh
# The man pages, as a C programmer reads them:
#  - every lpi_* function of the public header has a page in man/man3: its
#    family page, or a symbolic link to it, that names the function in NAME
#    and SYNOPSIS (no .so links: man -l resolves those from the current
#    directory only);
#  - every family page in man3 has RETURN VALUE and EXAMPLES; the EXAMPLES
#    program (the .EX/.EE blocks) compiles against include/ with warnings as
#    errors, runs against the built library, and fits 80 columns;
#  - every status a page names exists, and lpi_last_error(3) lists them all;
#  - every .TH line carries the same date and the header's version;
#  - liepoisson(7) and lpi(1) name the licence and the file that holds it;
#  - every page reads with `man -l` from the source tree, and is clean under
#    groff -ww and `mandoc -T lint -W warning`.
#   tests/check_man_pages.sh SOURCE_DIR [LIBRARY_DIR]
# With LIBRARY_DIR (where libliepoisson.so is) the examples are also linked
# and run, and must exit 0. CC (default cc) compiles them, with
# LPI_EXAMPLE_CFLAGS added when they are built to run (a sanitized library
# needs its runtime in the program too). man and mandoc are used when
# installed (scripts/install-deps installs them); with CI=true a missing one
# is a failure, so CI cannot pass without the lint.
set -u
root=$(cd "$1" && pwd)
libdir=${2:+$(cd "$2" && pwd)}
header="$root/include/liepoisson.h"
status=0
complain() { printf '%s\n' "$*"; status=1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The text of section $2 (.SH $2 up to the next .SH) of page $1.
section() { awk -v name="$2" '/^\.SH/ { on = ($0 == ".SH " name || $0 == ".SH \"" name "\"") ; next } on' "$1"; }

# ---- Coverage: every function of both headers has a page that documents it
names=$(grep -ho 'lpi_[a-z0-9_]*(' "$header" "$root/include/liepoisson_mpi.h" | tr -d '(' | sort -u)
for name in $names; do
    page="$root/man/man3/$name.3"
    if [ ! -e "$page" ]; then
        complain "missing man page: man/man3/$name.3 (a family page, or a symbolic link to one)"
        continue
    fi
    if [ -L "$page" ]; then
        target=$(readlink "$page")
        case "$target" in
        */*) complain "man/man3/$name.3 links to $target: link to a page in the same directory"; continue ;;
        esac
        if [ ! -f "$root/man/man3/$target" ] || [ -L "$root/man/man3/$target" ]; then
            complain "man/man3/$name.3 links to $target, which is not a page"; continue
        fi
    fi
    section "$page" NAME | tr ',' ' ' | grep -qw -- "$name" ||
        complain "man/man3/$name.3: NAME does not list $name"
    section "$page" SYNOPSIS | grep -q -- "$name(" ||
        complain "man/man3/$name.3: SYNOPSIS does not declare $name()"
done
for page in "$root"/man/man*/*.[1-9]; do
    if grep -q '^\.so ' "$page"; then
        complain "${page#"$root/"}: .so link; use a symbolic link (ln -s family.3 ${page##*/}), which man -l follows from any directory"
    fi
done

# ---- SEE ALSO: pages of this manual, each of which exists ------------------
# Other manuals' pages may not be installed (fftw3 ships no section 3), so
# they are named in the text instead.
for page in "$root"/man/man*/*.[1-9]; do
    [ -L "$page" ] && continue
    for ref in $(section "$page" "SEE ALSO" | grep -o '[A-Za-z_][A-Za-z0-9_.-]* *([0-9][a-z]*)' | tr -d ' '); do
        name=${ref%%(*}
        sec=${ref#*(}
        sec=${sec%)}
        [ -e "$root/man/man$sec/$name.$sec" ] ||
            complain "${page#"$root/"}: SEE ALSO names $ref, which is not a page of this manual"
    done
done

# ---- Statuses: only real ones, and the full list on lpi_last_error(3) -----
statuses=$(sed -n 's/^ *X(\(LPI_[A-Z_]*\), *[-+]\{0,1\}[0-9]*,.*/\1/p' "$header")
[ -n "$statuses" ] || complain "no status codes found in the LPI_STATUS_LIST of $header"
for used in $(cat "$root"/man/man*/*.[1-9] | grep -o 'LPI_ERR_[A-Z][A-Z_]*\|LPI_OK' | sort -u); do
    printf '%s\n' "$statuses" | grep -qx "$used" || complain "the man pages name $used, which is not a status of the header"
done
for code in $statuses; do
    section "$root/man/man3/lpi_last_error.3" DESCRIPTION | grep -q "^\.B $code\$" ||
        complain "man/man3/lpi_last_error.3 does not list $code with its value"
done

# ---- .TH: one date, and the header's version ------------------------------
version="liepoisson $(sed -n 's/^#define LPI_VERSION_MAJOR //p' "$header").$(sed -n \
    's/^#define LPI_VERSION_MINOR //p' "$header").$(sed -n 's/^#define LPI_VERSION_PATCH //p' "$header")"
dates=""
for page in "$root"/man/man*/*.[1-9]; do
    [ -L "$page" ] && continue
    rel=${page#"$root/"}
    base=${page##*/}
    th=$(grep -m1 '^\.TH ' "$page")
    # .TH TITLE SECTION DATE "SOURCE" "MANUAL"
    title=$(printf '%s\n' "$th" | awk '{ print $2 }')
    sec=$(printf '%s\n' "$th" | awk '{ print $3 }')
    date=$(printf '%s\n' "$th" | awk '{ print $4 }')
    source=$(printf '%s\n' "$th" | sed -n 's/^\.TH [^ ]* [^ ]* [^ ]* "\([^"]*\)" "liepoisson manual"$/\1/p')
    expected_title=$(printf '%s\n' "${base%.*}" | tr '[:lower:]' '[:upper:]')
    [ "$title" = "$expected_title" ] || complain "$rel: .TH title $title, expected $expected_title"
    [ "$sec" = "${base##*.}" ] || complain "$rel: .TH section $sec, expected ${base##*.}"
    printf '%s\n' "$date" | grep -qx '[0-9]\{4\}-[0-9][0-9]-[0-9][0-9]' || complain "$rel: .TH date '$date' is not YYYY-MM-DD"
    [ "$source" = "$version" ] ||
        complain "$rel: .TH must end with \"$version\" \"liepoisson manual\" (the version of include/liepoisson.h); it is: $th"
    dates="$dates$date $rel
"
done
if [ "$(printf '%s' "$dates" | awk '{ print $1 }' | sort -u | wc -l)" -ne 1 ]; then
    complain "the pages carry different dates (man/stamp-pages.sh sets one):"
    printf '%s' "$dates" | sort | sed 's/^/    /'
fi

# ---- The licence, named where a user looks for it -------------------------
head -n1 "$root/LICENSE" | grep -q '^BSD 3-Clause License$' || complain "LICENSE is not the BSD 3-Clause text"
for page in man/man7/liepoisson.7 man/man1/lpi.1; do
    copyright=$(section "$root/$page" COPYRIGHT | sed 's/\\-/-/g')
    if ! printf '%s\n' "$copyright" | grep -q 'BSD-3-Clause' || ! printf '%s\n' "$copyright" | grep -q 'LICENSE'; then
        complain "$page: COPYRIGHT must name BSD-3-Clause and the file LICENSE"
    fi
done

# ---- Family pages: RETURN VALUE, ERRORS, an EXAMPLES program that works --
cc=${CC:-cc}
programs=""
mpi_programs=""
examples_checked=compile
for page in "$root"/man/man3/*.3; do
    [ -L "$page" ] && continue
    rel=${page#"$root/"}
    grep -q '^\.SH "\{0,1\}RETURN VALUE"\{0,1\}$' "$page" || complain "$rel: no RETURN VALUE section"
    # Every function behind the C API wrapper can return these three.
    errors=$(section "$page" ERRORS)
    for code in LPI_ERR_NULL LPI_ERR_NO_MEMORY LPI_ERR_INTERNAL; do
        [ -z "$errors" ] || printf '%s\n' "$errors" | grep -q "^\.B $code\$" || complain "$rel: ERRORS does not list $code"
    done
    examples=$(section "$page" EXAMPLES)
    if [ -z "$examples" ]; then complain "$rel: no EXAMPLES section"; continue; fi
    # The program is the text of the .EX/.EE blocks with roff escapes undone;
    # a request inside a block would render differently from what compiles.
    program="$work/$(basename "$page" .3).c"
    printf '%s\n' "$examples" | awk '/^\.EE/ { code = 0 } code { print } /^\.EX/ { code = 1 }' >"$program"
    if grep -q "^[.']" "$program"; then
        complain "$rel: a roff request inside an .EX block of EXAMPLES:"; grep -n "^[.']" "$program"
        continue
    fi
    sed -i -e 's/\\&//g' -e 's/\\-/-/g' -e "s/\\\\(aq/'/g" -e 's/\\(dq/"/g' -e 's/\\e/\\/g' "$program"
    long=$(awk 'length($0) > 71 { print FILENAME ":" FNR ": " $0 }' "$program")
    [ -z "$long" ] || complain "$rel: EXAMPLES lines longer than 71 columns overflow an 80-column terminal:" "$long"
    if ! grep -q 'int main(' "$program"; then
        complain "$rel: EXAMPLES has no complete program (.EX ... int main( ... .EE)"; continue
    fi
    # A program of the MPI part builds with MPI (MPICC, set by the build when
    # it has MPI) and libliepoisson_mpi, and runs as a single process (without
    # LeakSanitizer: Open MPI keeps allocations until the process ends).
    if grep -q 'liepoisson_mpi.h' "$program"; then
        mpi_programs="$mpi_programs $program"
    else
        programs="$programs $program"
    fi
done
mpi_programs=${mpi_programs# }
if [ -n "$mpi_programs" ] && [ -n "${MPICC:-}" ]; then
    for program in $mpi_programs; do
        name=$(basename "$program" .c)
        if ! out=$($MPICC ${LPI_EXAMPLE_CFLAGS:-} -std=c99 -Wall -Wextra -Werror -I "$root/include" -c "$program" -o "$work/$name.o" 2>&1); then
            complain "man/man3/$name.3: the EXAMPLES program does not compile:"; printf '%s\n' "$out"
        elif [ -n "$libdir" ] && ! out=$($MPICC ${LPI_EXAMPLE_CFLAGS:-} "$work/$name.o" -L "$libdir" -lliepoisson_mpi -lm \
            -Wl,-rpath,"$libdir" -o "$work/$name.mpi" 2>&1 && cd "$work" &&
            ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" "./$name.mpi" 2>&1); then
            complain "man/man3/$name.3: the EXAMPLES program fails:"; printf '%s\n' "$out"
        fi
    done
fi
# One compiler run for all (its messages name the page: lpi_step.c is the
# program of man3/lpi_step.3): objects when they are to run, else a syntax
# check. The file names have no spaces; LPI_EXAMPLE_CFLAGS is a list.
if [ -n "$libdir" ]; then
    compile="-c ${LPI_EXAMPLE_CFLAGS:-}"
else
    compile=-fsyntax-only
fi
# shellcheck disable=SC2086
if [ -n "$programs" ] && ! out=$(cd "$work" && $cc -std=c99 -Wall -Wextra -Wpedantic -Werror $compile \
    -I "$root/include" $programs 2>&1); then
    complain "EXAMPLES programs that do not compile (NAME.c is the program of man3/NAME.3):"
    printf '%s\n' "$out"
elif [ -n "$libdir" ]; then
    examples_checked="compile and run"
    # Linked against the built library and run, each in a directory of its
    # own (some write files), all at once: an example that no longer works
    # fails here.
    for program in $programs; do
        name=$(basename "$program" .c)
        mkdir "$work/$name"
        (
            cd "$work/$name" || exit 1
            # shellcheck disable=SC2086
            if ! $cc ${LPI_EXAMPLE_CFLAGS:-} "$work/$name.o" -L "$libdir" -lliepoisson -lm \
                -Wl,-rpath,"$libdir" -o example >log 2>&1; then
                echo "does not link:" >failed
            elif ! ./example >log 2>&1; then
                echo "fails:" >failed
            fi
        ) &
    done
    wait
    for program in $programs; do
        name=$(basename "$program" .c)
        if [ -f "$work/$name/failed" ]; then
            complain "man/man3/$name.3: the EXAMPLES program $(cat "$work/$name/failed")"
            cat "$work/$name/log"
        fi
    done
fi

# ---- Rendering: groff, mandoc's lint, and man -l from the source tree -----
need_tool() {
    command -v "$1" >/dev/null 2>&1 && return 0
    if [ "${CI:-}" = true ]; then
        complain "$1 is not installed; CI must run $2 (scripts/install-deps installs it)"
    else
        echo "note: $1 is not installed, $2 skipped (scripts/install-deps installs it)"
    fi
    return 1
}
have_mandoc=0; need_tool mandoc "the lint" && have_mandoc=1
have_man=0; need_tool man "the man -l check" && have_man=1
# Each tool reads every page in one run; their messages name the file.
# shellcheck disable=SC2046 # the page names have no spaces
set -- $(cd "$root" && for page in man/man*/*.[1-9]; do [ -L "$page" ] || printf '%s\n' "$page"; done)
out=$(cd "$root" && groff -man -ww -z "$@" 2>&1)
[ -z "$out" ] || complain "groff: $out"
if [ $have_mandoc -eq 1 ]; then
    out=$(cd "$root" && mandoc -T lint -W warning "$@" 2>&1)
    [ -z "$out" ] || complain "$out"
fi
# What a user types in the tree (no pager, a fixed width and locale): every
# page, and one symbolic link (the others are checked above to point at a
# page beside them, which man -l then reads the same way). Page by page only
# on a failure, to name it.
if [ $have_man -eq 1 ]; then
    for link in "$root"/man/man3/*.3; do [ -L "$link" ] && set -- "$@" "${link#"$root/"}" && break; done
    man_l() { (cd "$root" && LC_ALL=C MANWIDTH=80 MANPAGER=cat PAGER=cat man -l "$@" 2>"$work/man.err"); }
    if [ "$(man_l "$@" | grep -c '^NAME$')" -ne $# ] || [ -s "$work/man.err" ]; then
        for rel in "$@"; do
            out=$(man_l "$rel")
            if [ -s "$work/man.err" ]; then complain "man -l $rel:"; cat "$work/man.err"; fi
            printf '%s\n' "$out" | grep -q '^NAME$' || complain "man -l $rel shows no NAME section"
        done
    fi
fi

[ $status -eq 0 ] && echo "man pages: $(printf '%s\n' "$names" | wc -w) functions covered, examples $examples_checked, one date and version, all pages render cleanly"
exit $status
