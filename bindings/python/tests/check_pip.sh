#!/bin/sh
# `pip install bindings/python` offline, as the README says: into a venv that
# sees the system's setuptools and wheel, with no build isolation and no
# package index. The installed package carries its version (the library's),
# its licence, py.typed, and runs against LIBRARY. Skipped (77) when PYTHON
# lacks pip, setuptools, wheel or venv.
# Usage: check_pip.sh SOURCE_DIR PYTHON LIBRARY
set -eu
source_dir=$1 python=$2 library=$3
work=$(mktemp -d "${TMPDIR:-/tmp}/lpi-pip.XXXXXX")
trap 'rm -rf "$work"' EXIT
fail() { echo "check_pip: $*"; exit 1; }
for module in setuptools wheel venv pip; do
    "$python" -c "import $module" 2>/dev/null || { echo "check_pip: $python has no $module: skipped"; exit 77; }
done
# A copy: setuptools builds in the source directory (build/, *.egg-info).
cp -R "$source_dir/bindings/python" "$work/src"
rm -rf "$work/src/build" "$work/src"/*.egg-info
"$python" -m venv --system-site-packages --without-pip "$work/venv"
"$work/venv/bin/python" -m pip install --no-build-isolation --no-index "$work/src" >"$work/pip.log" 2>&1 ||
    { cat "$work/pip.log"; fail "pip install failed"; }
header_version=$(sed -n 's/^#define LPI_VERSION_\(MAJOR\|MINOR\|PATCH\) \([0-9]*\).*/\2/p' "$source_dir/include/liepoisson.h" | paste -sd.)
(cd "$work" && env LIEPOISSON_LIBRARY="$library" PYTHONPATH= "$work/venv/bin/python" -c '
import importlib.metadata as md, os, sys, liepoisson as lp
where = os.path.dirname(lp.__file__)
assert where.startswith(sys.prefix), "imported from " + where
assert os.path.isfile(os.path.join(where, "py.typed")), "no py.typed"
meta = md.metadata("liepoisson")
assert meta["Version"] == lp.version == sys.argv[1], (meta["Version"], lp.version, sys.argv[1])
assert meta["License"] == "BSD-3-Clause", meta["License"]
with lp.Pendulum() as p:
    p.state = [0.6, -0.8, 1.2]
    assert p.step(0.01, 100) == 100
print("pip: liepoisson", meta["Version"], "(" + meta["License"] + ") installed in a venv offline, runs")
' "$header_version") || fail "the pip-installed package is wrong"
