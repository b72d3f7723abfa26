#!/bin/sh
# Every lpi_* function of include/liepoisson.h is bound by the Python, Fortran
# and Julia bindings, and the bindings' versions match the header's. A binding
# counts a function only where it really declares it:
#   Python   "lpi_name": (...)            in liepoisson/_lib.py (the prototype table)
#   Fortran  bind(C, name="lpi_name")     in liepoisson.f90
#   Julia    :lpi_name                    in LiePoisson.jl (a ccall symbol)
set -u
root=$(cd "$1" && pwd)
header="$root/include/liepoisson.h"
python="$root/bindings/python/liepoisson/_lib.py"
fortran="$root/bindings/fortran/liepoisson.f90"
julia="$root/bindings/julia/LiePoisson.jl/src/LiePoisson.jl"
status=0
names=$(grep -o '^LPI_API[^(]*[ *]lpi_[a-z0-9_]*(' "$header" | grep -o 'lpi_[a-z0-9_]*' | sort -u)
[ -n "$names" ] || { echo "no lpi_* functions found in $header"; exit 1; }

report() {  # binding file pattern-template
    missing=""
    for name in $names; do
        pattern=$(printf '%s' "$3" | sed "s/NAME/$name/")
        grep -q -- "$pattern" "$2" 2>/dev/null || missing="$missing $name"
    done
    if [ -n "$missing" ]; then
        echo "$1 binding ($2) lacks:$missing"
        status=1
    fi
}
report Python "$python" "\"NAME\": ("
report Fortran "$fortran" "name=\"NAME\")"
report Julia "$julia" ":NAME\b"

version=$(sed -n 's/^#define LPI_VERSION_\(MAJOR\|MINOR\|PATCH\) \([0-9]*\).*/\2/p' "$header" | paste -sd.)
for f in "$root/bindings/python/pyproject.toml" "$root/bindings/julia/LiePoisson.jl/Project.toml"; do
    grep -q "^version = \"$version\"" "$f" || { echo "$f: version is not $version (the header's)"; status=1; }
done
[ $status -eq 0 ] && echo "bindings: all $(echo "$names" | wc -w) functions bound in Python, Fortran and Julia"
exit $status
