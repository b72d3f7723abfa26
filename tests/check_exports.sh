#!/bin/sh
# The shared library exports nothing but lpi_* and carries the expected SONAME.
lib="$1"; major="$2"
bad=$(nm -D --defined-only "$lib" | awk '{print $NF}' | grep -v '^lpi_')
if [ -n "$bad" ]; then
    echo "exported symbols outside lpi_*:"; echo "$bad"; exit 1
fi
count=$(nm -D --defined-only "$lib" | grep -c ' lpi_')
[ "$count" -gt 0 ] || { echo "no lpi_ symbols exported"; exit 1; }
soname=$(readelf -d "$lib" | sed -n 's/.*Library soname: \[\(.*\)\].*/\1/p')
[ "$soname" = "libliepoisson.so.$major" ] || { echo "SONAME is '$soname', expected libliepoisson.so.$major"; exit 1; }
echo "exports: $count lpi_* symbols, nothing else; SONAME $soname"
