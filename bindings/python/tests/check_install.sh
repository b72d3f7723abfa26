#!/bin/sh
# `cmake --install` (what make install runs) puts the Python package where the
# interpreter looks under the prefix, and that package loads the library
# installed with it: no LIEPOISSON_LIBRARY, no LD_LIBRARY_PATH, from a prefix
# that was moved afterwards, and from a DESTDIR staging tree (which records the
# final path, not the staging one).
# Usage: check_install.sh BUILD PYTHON CMAKE
set -eu
build=$1 python=$2 cmake=$3
work=$(mktemp -d "${TMPDIR:-/tmp}/lpi-pyinstall.XXXXXX")
trap 'rm -rf "$work"' EXIT
fail() { echo "check_install (Python): $*"; exit 1; }
unset LIEPOISSON_LIBRARY LD_LIBRARY_PATH PYTHONHOME

# install PREFIX [DESTDIR]: prints the package directory the install reported.
install() {
    DESTDIR=${2:-} "$cmake" --install "$build" --prefix "$1" >"$work/install.log" 2>&1 ||
        { cat "$work/install.log"; fail "install to $1 failed"; }
    sed -n 's/^-- liepoisson: Python package in \(.*\) (.*)$/\1/p' "$work/install.log"
}
# steps SITE_DIR: a clean interpreter steps a rigid body and prints the library it loaded.
steps() {
    (cd "$work" && env PYTHONPATH="$1" PYTHONDONTWRITEBYTECODE=1 "$python" -c '
import os, liepoisson as lp
with lp.RigidBody(1.0, 2.0, 3.0) as b:
    b.state = [1.0, 0.5, -0.3]
    c0 = b.casimirs()[0]
    assert b.step(0.01, 1000) == 1000
    assert abs(b.casimirs()[0] - c0) < 1e-13, "Casimir drift"
print(os.path.realpath(lp._lib.lib._name))') || fail "the installed package does not run from $1"
}

prefix=$work/prefix
package=$(install "$prefix")
case "$package" in "$prefix"/lib/*/liepoisson) ;; *) fail "package installed in '$package', not under $prefix/lib";; esac
for f in __init__.py _lib.py _install.py py.typed; do
    [ -f "$package/$f" ] || fail "missing $package/$f"
done
installed=$(readlink -f "$(find "$prefix" -name 'libliepoisson.so.[0-9]*' -type l | head -1)")
loaded=$(steps "$(dirname "$package")")
[ "$loaded" = "$installed" ] || fail "the installed package loads '$loaded', not the library installed with it"

# Moved: found relative to the package.
mv "$prefix" "$work/moved"
moved=$work/moved${package#"$prefix"}
case "$(steps "$(dirname "$moved")")" in "$work/moved/"*) ;; *) fail "a moved prefix loads the library from elsewhere";; esac

# Staged: the recorded absolute path is the final one.
staged=$(install /opt/liepoisson "$work/stage")
grep -qx 'LIBRARY = "/opt/liepoisson/lib[^"]*/libliepoisson.so.[0-9]*"' "$work/stage$staged/_install.py" ||
    fail "the staged _install.py records: $(grep '^LIBRARY =' "$work/stage$staged/_install.py")"
case "$(steps "$(dirname "$work/stage$staged")")" in "$work/stage/opt/liepoisson/"*) ;; *) fail "a staged package loads the library from elsewhere";; esac
echo "python install: $package imports with no LIEPOISSON_LIBRARY and loads the library installed with it (moved and staged too)"
