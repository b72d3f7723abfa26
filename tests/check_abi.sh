#!/bin/sh
# ABI check of the shared library against the committed baseline.
#   check_abi.sh ROOT LIB            fails on an incompatible change
#   check_abi.sh --update ROOT LIB   rewrites the baseline (make abi-baseline)
# The baseline (abi/liepoisson.abi, libabigail's abidw) holds the exported
# lpi_* functions with the types of their parameters and results; what varies
# with the compiler is left out (abi/suppressions.ini). Removed functions and
# changed parameter or result types fail; added functions are compatible. The
# status codes'
# values are ABI too (abi/status_codes.txt): existing codes must keep their
# values, new ones may be appended.
set -u
update=0
if [ "${1:-}" = "--update" ]; then update=1; shift; fi
root=$(cd "$1" && pwd); lib="$2"
baseline="$root/abi/liepoisson.abi"
codes="$root/abi/status_codes.txt"
suppr="$root/abi/suppressions.ini"

if ! command -v abidw >/dev/null || ! command -v abidiff >/dev/null; then
    echo "abidw/abidiff not found: install abigail-tools (scripts/install-deps)"
    exit 77
fi
if ! readelf -S "$lib" | grep -q '\.debug_info'; then
    echo "$lib has no DWARF (the C shims are built with -g; was this build configured elsewhere?)"
    exit 77
fi

status_codes() {
    sed -n 's/^ *X(\(LPI_[A-Z_]*\), *\(-*[0-9]*\),.*/\1 \2/p' "$root/include/liepoisson.h"
}

if [ $update -eq 1 ]; then
    abidw --suppressions "$suppr" --headers-dir "$root/include" --drop-private-types \
        --no-corpus-path --no-comp-dir-path --no-show-locs --no-elf-needed \
        --type-id-style hash --out-file "$baseline" "$lib" || exit 1
    status_codes > "$codes"
    echo "wrote $baseline ($(grep -c '<elf-symbol ' "$baseline") functions) and $codes ($(wc -l < "$codes") codes)"
    exit 0
fi

[ -f "$baseline" ] || { echo "no baseline $baseline (run: make abi-baseline)"; exit 1; }
# abidiff ranks a changed parameter or result type as a mere "change" (4),
# yet for a C interface every such change breaks callers. So: with added
# functions left out, any change at all fails; additions alone only report.
diff() {
    abidiff --suppressions "$suppr" --hd2 "$root/include" --drop-private-types \
        --no-show-locs "$@" "$baseline" "$lib" 2>&1
}
failed=0
out=$(diff --no-added-syms)
rc=$?
if [ $rc -ne 0 ]; then
    echo "$out"
    echo "abidiff exit status $rc: the existing interface changed (incompatible) against abi/liepoisson.abi"
    failed=1
else
    out=$(diff)
    if [ $? -ne 0 ]; then
        echo "$out"
        echo "compatible ABI change (additions only); refresh the baseline with: make abi-baseline"
    fi
fi

current=$(status_codes)
missing=$(echo "$current" | grep -vxF -f - "$codes")
if [ -n "$missing" ]; then
    echo "status codes removed or renumbered (they are ABI):"; echo "$missing"
    failed=1
fi
[ $failed -eq 0 ] && echo "ABI: $(grep -c '<elf-symbol ' "$baseline") baseline functions, no incompatible change; $(wc -l < "$codes") status codes kept"
exit $failed
