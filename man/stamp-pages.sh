#!/bin/sh
# Sets the date and the version on the .TH line of every page: the date given
# (YYYY-MM-DD, default today) and the version of include/liepoisson.h.
# tests/check_man_pages.sh requires one date and that version on every page.
#   man/stamp-pages.sh [DATE]
set -eu
cd "$(dirname "$0")/.."
date=${1:-$(date +%Y-%m-%d)}
echo "$date" | grep -qx '[0-9]\{4\}-[0-9][0-9]-[0-9][0-9]' || { echo "usage: $0 [YYYY-MM-DD]" >&2; exit 2; }
field() { sed -n "s/^#define LPI_VERSION_$1 //p" include/liepoisson.h; }
version="$(field MAJOR).$(field MINOR).$(field PATCH)"
for page in man/man*/*.[1-9]; do
    [ -L "$page" ] && continue
    sed -i "s/^\(\.TH [^ ]* [^ ]*\) .*/\1 $date \"liepoisson $version\" \"liepoisson manual\"/" "$page"
done
