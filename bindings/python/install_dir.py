"""Prints where `make install` puts the Python package for a prefix: the
directory this interpreter imports from under that prefix (for /usr on Debian
lib/python3/dist-packages, for /usr/local lib/python3.X/dist-packages), else the
standard layout lib/python3.X/site-packages, which is then to be added to
PYTHONPATH. The second line says which.

    python3 install_dir.py PREFIX
"""
import os
import sys
import sysconfig


def install_dir(prefix):
    prefix = os.path.abspath(prefix)
    for entry in sys.path:
        entry = os.path.abspath(entry or ".")
        rel = os.path.relpath(entry, prefix)
        if rel.startswith("lib" + os.sep + "python") and os.path.basename(rel) in ("site-packages", "dist-packages"):
            return entry, "imported"
    return sysconfig.get_path("purelib", "posix_prefix", vars={"base": prefix, "platbase": prefix}), "PYTHONPATH"


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: install_dir.py PREFIX")
    path, how = install_dir(sys.argv[1])
    print(path)
    print(how)
