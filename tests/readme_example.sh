#!/bin/sh
# Compiles and runs the C example in README.md (the block between the
# example-begin and example-end markers) against the built library.
# LPI_EXAMPLE_CFLAGS adds compiler flags (a sanitized library needs its
# sanitizer runtime linked into the program too).
set -e
readme="$1"; cc="$2"; include="$3"; libdir="$4"; work="$5"
mkdir -p "$work"
sed -n '/<!-- example-begin -->/,/<!-- example-end -->/p' "$readme" | sed '/^<!--/d;/^```/d' > "$work/example.c"
[ -s "$work/example.c" ] || { echo "no example found in $readme"; exit 1; }
lines=$(wc -l < "$work/example.c")
"$cc" -std=c99 -Wall -Wextra -Werror ${LPI_EXAMPLE_CFLAGS:-} -I"$include" "$work/example.c" -L"$libdir" -lliepoisson -lm \
    -Wl,-rpath,"$libdir" -o "$work/example"
"$work/example"
echo "README example: $lines lines, compiled with -Werror and ran"
