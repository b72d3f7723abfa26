#!/bin/sh
# check_lpi_data.sh LPI OUTDIR
# lpi run sine-euler keeps its run as data: .npy files (NumPy format 1.0,
# '<f8'/'<i8', header padded to 64 bytes) and, when built with HDF5, one .h5
# file that h5py (and xarray, when installed) reads. Checked against numpy
# when a Python with numpy is found (the energy recomputed from the vorticity
# snapshot by FFT), byte by byte otherwise. --init takes an N x N grid from
# .npy (float64, float32, int64, int32, either order) or from a run's .h5, and refuses a
# bad file with exit status 1 (unreadable) or 2 (no usable N x N grid).
# Exits 77 without sine-Euler (FFTW).
set -eu
lpi="$1"; out="$2"
rm -rf "$out"
mkdir -p "$out"
fail() { echo "FAIL: $*"; exit 1; }
run() { "$lpi" run sine-euler --N 9 --dt 0.05 --steps 12 --every 3 --snapshots 2 "$@" >/dev/null; }
if ! run --out "$out/npy" --format npy 2>"$out/err"; then
    grep -q "not available in this build" "$out/err" && { echo "SKIP: no sine-Euler in this build"; exit 77; }
    cat "$out/err"; fail "lpi run sine-euler"
fi
# HDF5 is left out only where lpi says it was built without it: a build with
# HDF5 whose .h5 run fails fails here (it used to leave the HDF5 checks out).
have_h5=1
if ! run --out "$out/h5" --format h5 2>"$out/err"; then
    grep -q "built without HDF5" "$out/err" || { cat "$out/err"; fail "lpi run sine-euler --format h5"; }
    have_h5=0
fi
python=""
for p in python3 /usr/bin/python3; do
    if "$p" -c 'import numpy' 2>/dev/null; then python=$p; break; fi
done

# Byte level: the .npy header of the snapshots (5 rows, snapshots at rows 0, 2, 4).
v="$out/npy/sine-euler/vorticity.npy"
[ "$(head -c 8 "$v" | od -An -tx1 | tr -d ' \n')" = 934e554d50590100 ] || fail "vorticity.npy: no NumPy 1.0 magic"
header_len=$(head -c 10 "$v" | tail -c 2 | od -An -tu2 --endian=little | tr -d ' ')
[ $(((10 + header_len) % 64)) -eq 0 ] || fail "vorticity.npy: header of $header_len bytes, not padded to 64"
header=$(head -c $((10 + header_len)) "$v" | tail -c "$header_len")
case $header in
"{'descr': '<f8', 'fortran_order': False, 'shape': (3, 9, 9), }"*) ;;
*) fail "vorticity.npy header: $header" ;;
esac
[ "$(wc -c < "$v")" -eq $((10 + header_len + 3 * 81 * 8)) ] || fail "vorticity.npy: size"
grep -q '"method": "leapfrog"' "$out/npy/sine-euler/attributes.json" || fail "attributes.json"
if [ "$have_h5" = 1 ]; then
    [ "$(head -c 8 "$out/h5/sine-euler.h5" | od -An -tx1 | tr -d ' \n')" = 894844460d0a1a0a ] || fail "no HDF5 signature"
fi
# The raw data is kept beside the images drawn from it.
if command -v gnuplot >/dev/null 2>&1; then
    for f in sine-euler_vorticity_000000.png sine-euler_vorticity_000012.svg; do [ -s "$out/npy/$f" ] || fail "no $f"; done
    [ -s "$v" ] || fail "the snapshot data was removed after plotting"
fi

# Exit statuses of bad --init files.
refused() {  # refused STATUS MESSAGE-PART lpi-run-arguments...
    want=$1 what=$2; shift 2
    rc=0
    "$lpi" run "$@" --steps 1 --out "$out/bad" >/dev/null 2>"$out/err" || rc=$?
    [ "$rc" -eq "$want" ] || { cat "$out/err"; fail "lpi run $*: exit status $rc, expected $want"; }
    grep -q -e "$what" "$out/err" || { cat "$out/err"; fail "lpi run $*: no message with '$what'"; }
}
echo "not a grid" > "$out/text.npy"
head -c 100 "$v" > "$out/truncated.npy"
refused 1 "No such file" sine-euler --init "$out/missing.npy"
refused 1 "magic" sine-euler --init "$out/text.npy"
refused 1 "truncated" sine-euler --init "$out/truncated.npy"
refused 2 "shape (3, 9, 9)" sine-euler --init "$v"
refused 2 "not (N, N)" sine-euler --init "$out/npy/sine-euler/time.npy"
refused 2 "exclude" sine-euler --init "$v" --resume "$out/x.lpi"
if [ "$have_h5" = 1 ]; then
    # A run's .h5: the last snapshot; --N must agree with it.
    refused 2 "but --N is 11" sine-euler --N 11 --init "$out/h5/sine-euler.h5"
    refused 2 "--init: rigid-body does not take it" rigid-body --init "$out/h5/sine-euler.h5"
    head -c 3000 "$out/h5/sine-euler.h5" > "$out/truncated.h5"
    refused 1 "HDF5 cannot" sine-euler --init "$out/truncated.h5"
    "$lpi" run rigid-body --steps 2 --format h5 --out "$out/rb" >/dev/null
    refused 2 "no dataset /init or /vorticity" sine-euler --init "$out/rb/rigid-body.h5"
    # The run's own data as --init: the run would replace the grid it starts
    # from, and the run that made it.
    cp "$out/h5/sine-euler.h5" "$out/own.h5"
    rc=0; "$lpi" run sine-euler --N 9 --init "$out/h5/sine-euler.h5" --steps 1 --out "$out/h5" >/dev/null \
        2>"$out/err" || rc=$?
    [ "$rc" -eq 2 ] && grep -q -e "--init .*which this run writes" "$out/err" ||
        { cat "$out/err"; fail "--init the run's own data: exit status $rc, expected 2"; }
    cmp -s "$out/own.h5" "$out/h5/sine-euler.h5" || fail "--init the run's own data: the data was replaced"
fi
# A command under 1 GB of address space (a subshell); without the limit where
# lpi runs under AddressSanitizer, which reserves terabytes of it.
limited() {
    if ldd "$lpi" 2>/dev/null | grep -q libasan; then "$@"; else (ulimit -v 1000000; "$@"); fi
}
# A header that claims more data than the file holds is refused before
# anything is allocated for it (under 1 GB of address space, 2 GiB claimed):
# a .npy of 208 bytes claiming 16383 x 16383 doubles, and the run's .h5 with
# /vorticity's dimensions (3, 9, 9) made (1, 16383, 16383).
dict="{'descr': '<f8', 'fortran_order': False, 'shape': (16383, 16383), }"
pad=$((128 - 10 - ${#dict} - 1))
{ printf '\223NUMPY\001\000\166\000%s%*s\n' "$dict" "$pad" ""; head -c 80 /dev/zero; } > "$out/claims.npy"
[ "$(wc -c < "$out/claims.npy")" -eq 208 ] || fail "claims.npy: the test wrote $(wc -c < "$out/claims.npy") bytes"
limited refused 1 "truncated" sine-euler --init "$out/claims.npy"
# The header is read as NumPy reads it (a Python literal with exactly the keys
# descr, fortran_order and shape): a header NumPy refuses, or one that says
# two things (a key twice: NumPy keeps the last) or gives a negative size, is
# refused (exit status 1) and not read some other way. Each
# file holds the 72 bytes of a 3 x 3 float64 grid; the first is readable.
header_case() {  # header_case NAME DICT
    pad=$((128 - 10 - ${#2} - 1))
    { printf '\223NUMPY\001\000\166\000%s%*s\n' "$2" "$pad" ""; head -c 72 /dev/zero; } > "$out/$1.npy"
}
# More dimensions than NumPy has (64): refused, by name (they were read, and
# a header of thousands of them written back wrapped format 1.0's length).
dims=$(printf '1, %.0s' $(seq 65))
dict="{'descr': '<f8', 'fortran_order': False, 'shape': (${dims%, }), }"
pad=$((384 - 10 - ${#dict} - 1))
{ printf '\223NUMPY\001\000\166\001%s%*s\n' "$dict" "$pad" ""; head -c 8 /dev/zero; } > "$out/dims.npy"
[ "$(wc -c < "$out/dims.npy")" -eq 392 ] || fail "dims.npy: the test wrote $(wc -c < "$out/dims.npy") bytes"
refused 1 "65 dimensions, more than NumPy's 64" sine-euler --init "$out/dims.npy"
header_case plain "{\"descr\":\"<f8\",\"fortran_order\":True,\"shape\":(3,3)}"
"$lpi" run sine-euler --init "$out/plain.npy" --steps 1 --out "$out/plain" >/dev/null 2>"$out/err" ||
    { cat "$out/err"; fail "lpi run --init with a header in double quotes, without spaces"; }
o="'fortran_order': False"
header_case no_comma "{'descr': '<f8', $o, 'shape': (3 3), }"
header_case no_tuple "{'descr': '<f8', $o, 'shape': (9), }"
header_case leading_zero "{'descr': '<f8', $o, 'shape': (03, 3), }"
header_case negative "{'descr': '<f8', $o, 'shape': (-3, 3), }"
header_case twice "{'descr': '<i8', 'descr': '<f8', $o, 'shape': (3, 3), }"
header_case other_key "{'descr': '<f8', $o, 'shape': (3, 3), 'x': 1}"
header_case unclosed "{'descr': '<f8', $o, 'shape': (3, 3), "
header_case after "{'descr': '<f8', $o, 'shape': (3, 3)} x"
header_case no_order "{'descr': '<f8', 'shape': (3, 3), }"
header_case not_bool "{'descr': '<f8', 'fortran_order': 0, 'shape': (3, 3), }"
refused 1 "shape is not a tuple" sine-euler --init "$out/no_comma.npy"
refused 1 "shape is not a tuple" sine-euler --init "$out/no_tuple.npy"
refused 1 "shape is not a tuple" sine-euler --init "$out/leading_zero.npy"
refused 1 "shape is not a tuple" sine-euler --init "$out/negative.npy"
refused 1 "the key 'descr' twice" sine-euler --init "$out/twice.npy"
refused 1 "a key 'x'" sine-euler --init "$out/other_key.npy"
refused 1 "no closing" sine-euler --init "$out/unclosed.npy"
refused 1 "more after its dictionary" sine-euler --init "$out/after.npy"
refused 1 "no fortran_order" sine-euler --init "$out/no_order.npy"
refused 1 "fortran_order is not True or False" sine-euler --init "$out/not_bool.npy"
le8() { printf "\\$(printf %o "$1")\\$(printf %o "$2")\\000\\000\\000\\000\\000\\000"; }  # le8 LOW HIGH: 8 bytes
zeros='\x00\x00\x00\x00\x00\x00\x00'
dims="\\x03$zeros\\x09$zeros\\x09$zeros"
if [ "$have_h5" = 1 ] && at=$(LC_ALL=C grep -obUaP "$dims" "$out/h5/sine-euler.h5" | cut -d: -f1) && [ -n "$at" ]; then
    cp "$out/h5/sine-euler.h5" "$out/claims.h5"
    for offset in $at; do
        { le8 1 0; le8 255 63; le8 255 63; } | dd of="$out/claims.h5" bs=1 seek="$offset" conv=notrunc 2>/dev/null
    done
    limited refused 1 "vorticity claims more values than the file holds" sine-euler --init "$out/claims.h5"
fi
# An integer grid (NumPy's int32, written here byte by byte: 3 x 3, the
# header padded to 64 bytes) starts a run, and the help says that it does.
dict="{'descr': '<i4', 'fortran_order': False, 'shape': (3, 3), }"
pad=$((128 - 10 - ${#dict} - 1))
{ printf '\223NUMPY\001\000\166\000%s%*s\n' "$dict" "$pad" ""
  for k in 0 1 2 3 4 5 6 7 8; do printf "\\$(printf %o $k)\\000\\000\\000"; done; } > "$out/int3.npy"
[ "$(wc -c < "$out/int3.npy")" -eq $((128 + 36)) ] || fail "int3.npy: the test wrote $(wc -c < "$out/int3.npy") bytes"
"$lpi" run sine-euler --init "$out/int3.npy" --steps 1 --out "$out/int3" >/dev/null 2>"$out/err" ||
    { cat "$out/err"; fail "lpi run --init with an int32 grid"; }
"$lpi" run --help | grep -q "int64 or int32" || fail "lpi run --help does not name the integer dtypes --init reads"

if [ -z "$python" ]; then
    echo "PASS (byte level; no Python with numpy): lpi run data and --init"
    exit 0
fi
"$python" - "$lpi" "$out" "$have_h5" <<'EOF'
import json, math, os, subprocess, sys
import numpy as np
lpi, out, have_h5 = sys.argv[1], sys.argv[2], sys.argv[3] == "1"
N = 9

def energy(grid):
    # H = 1/2 sum_{m != 0} |w_m|^2 / |m|^2, w_m the Fourier coefficients of
    # the grid w(2 pi a / N, 2 pi b / N), |m| from the representative in -4..4.
    w = np.fft.fft2(grid) / N**2
    m = np.fft.fftfreq(N, 1.0 / N)
    m2 = m[:, None]**2 + m[None, :]**2
    m2[0, 0] = np.inf
    return 0.5 * np.sum(np.abs(w)**2 / m2)

def load_npy(folder):
    return {n[:-4]: np.load(os.path.join(folder, n)) for n in os.listdir(folder) if n.endswith(".npy")}

runs = {"npy": load_npy(os.path.join(out, "npy", "sine-euler"))}
attrs = json.load(open(os.path.join(out, "npy", "sine-euler", "attributes.json")))
assert attrs["N"] == N and attrs["dt"] == 0.05 and attrs["scene"] == "sine-euler", attrs
if have_h5:
    try:
        import h5py
    except ImportError:
        h5py = None
        print("no h5py: the .h5 file is checked by its signature only")
    if h5py:
        with h5py.File(os.path.join(out, "h5", "sine-euler.h5"), "r") as f:
            runs["h5"] = {k: f[k][()] for k in f}
            assert f.attrs["method"] == "leapfrog" and f.attrs["N"] == N and f.attrs["dt"] == 0.05, dict(f.attrs)
            assert f["vorticity"].dims[0][0].name == "/snapshot_time", "no dimension scale on vorticity"
            assert f["energy"].dims[0][0].name == "/time"
        try:
            import h5netcdf, xarray
        except ImportError:
            xarray = None
            print("no xarray with h5netcdf: skipped reading through xarray")
        if xarray:
            ds = xarray.open_dataset(os.path.join(out, "h5", "sine-euler.h5"), engine="h5netcdf")
            assert ds["vorticity"].dims == ("snapshot_time", "x", "y"), ds["vorticity"].dims
            print("xarray reads it:", dict(ds.sizes))
csv = np.loadtxt(os.path.join(out, "npy", "sine-euler.csv"), delimiter=",", skiprows=1, ndmin=2)
for fmt, d in runs.items():
    assert d["vorticity"].shape == (3, N, N) and d["vorticity"].dtype == np.float64, fmt
    assert list(d["step"]) == [0, 3, 6, 9, 12] and d["step"].dtype == np.int64, (fmt, d["step"])
    assert list(d["snapshot_step"]) == [0, 6, 12], (fmt, d["snapshot_step"])
    # The rows are the CSV's, to the bit.
    assert np.array_equal(d["energy"], csv[:, 2]) and np.array_equal(d["time"], csv[:, 1]), fmt
    assert np.array_equal(d["casimirs"], csv[:, 4:]), fmt
    # Each snapshot is the state whose energy the row at its step holds.
    for k, step in enumerate(d["snapshot_step"]):
        row = list(d["step"]).index(step)
        e = energy(d["vorticity"][k])
        assert abs(e - d["energy"][row]) < 1e-13 * abs(e), (fmt, step, e, d["energy"][row])
    assert abs(d["x"][1] - 2 * math.pi / N) < 1e-15, fmt
    print(f"{fmt}: rows and snapshots agree with the CSV and with the energy computed by FFT")
if "h5" in runs:
    for k in runs["npy"]:
        assert np.array_equal(runs["npy"][k], runs["h5"][k]), k

# --init: a grid w(x, y) = cos(x) + 0.5 sin(2 y) + 0.3 cos(x + y): the run's
# first snapshot is that grid and its energy the energy computed here, for
# float64 and float32, C and Fortran order; integer grids (as documented) are
# read as float64.
a = np.arange(N) * 2 * np.pi / N
grid = np.cos(a)[:, None] + 0.5 * np.sin(2 * a)[None, :] + 0.3 * np.cos(a[:, None] + a[None, :])
cases = {"f8": grid, "f4": grid.astype(np.float32), "fortran": np.asfortranarray(grid),
         "i4": np.round(10 * grid).astype(np.int32), "i8": np.round(10 * grid).astype(np.int64)}
for name, g in cases.items():
    path = os.path.join(out, f"init_{name}.npy")
    np.save(path, g)
    folder = os.path.join(out, f"init_{name}")
    subprocess.run([lpi, "run", "sine-euler", "--init", path, "--dt", "0.05", "--steps", "4", "--every", "2",
                    "--snapshots", "1", "--format", "npy", "--out", folder], check=True, stdout=subprocess.DEVNULL)
    d = load_npy(os.path.join(folder, "sine-euler"))
    expected = np.asarray(g, dtype=np.float64)
    assert np.max(np.abs(d["vorticity"][0] - expected)) < 1e-13, name
    assert abs(d["energy"][0] - energy(expected)) < 1e-13 * energy(expected), name
# The topography scene writes its h beside q = w + h: the energy of each
# snapshot, 1/2 sum |q_m - h_m|^2 / |m|^2 less the same of h alone, is the
# row's (a wrong h, or none, fails it).
folder = os.path.join(out, "topography")
subprocess.run([lpi, "run", "topography", "--N", str(N), "--dt", "0.05", "--steps", "6", "--every", "2",
                "--snapshots", "1", "--format", "npy", "--out", folder], check=True, stdout=subprocess.DEVNULL)
d = load_npy(os.path.join(folder, "topography"))
h = d["topography"]
assert h.shape == (N, N) and abs(np.mean(h**2) - 1.0) < 1e-13, h.shape  # sum |h_m|^2 = 1
for k, step in enumerate(d["snapshot_step"]):
    row = list(d["step"]).index(step)
    e = energy(d["vorticity"][k] - h) - energy(h)
    assert abs(e - d["energy"][row]) < 1e-13 * abs(e), (step, e, d["energy"][row])
if have_h5 and h5py:
    subprocess.run([lpi, "run", "topography", "--N", str(N), "--steps", "2", "--out", folder], check=True,
                   stdout=subprocess.DEVNULL)
    with h5py.File(os.path.join(folder, "topography.h5"), "r") as f:
        assert np.array_equal(f["topography"][()], h) and f["topography"].dims[0][0].name == "/x"
print("topography: its h is written with the data, and q - h has the rows' energy")
usage = subprocess.run([lpi, "run", "--help"], check=True, capture_output=True).stdout.decode()
assert "int64" in usage and "int32" in usage, "lpi run --help does not name the integer dtypes --init reads"
print("--init: .npy float64, float32, int64, int32 and Fortran order start from the given grid")
bad = os.path.join(out, "nan.npy")
g = grid.copy(); g[2, 3] = np.nan
np.save(bad, g)
rc = subprocess.run([lpi, "run", "sine-euler", "--init", bad, "--steps", "1", "--out", os.path.join(out, "bad")],
                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
assert rc.returncode == 2 and b"--init" in rc.stderr, rc
np.save(bad, np.zeros((8, 8)))
rc = subprocess.run([lpi, "run", "sine-euler", "--init", bad, "--steps", "1", "--out", os.path.join(out, "bad")],
                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
assert rc.returncode == 2 and b"N odd" in rc.stderr, rc
np.save(bad, grid.astype(">f8"))
rc = subprocess.run([lpi, "run", "sine-euler", "--init", bad, "--steps", "1", "--out", os.path.join(out, "bad")],
                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
assert rc.returncode == 1 and b">f8" in rc.stderr, rc
if "h5" in runs:
    # A run's .h5 continues from its last snapshot.
    folder = os.path.join(out, "from_h5")
    subprocess.run([lpi, "run", "sine-euler", "--init", os.path.join(out, "h5", "sine-euler.h5"), "--steps", "2",
                    "--snapshots", "1", "--format", "npy", "--out", folder], check=True, stdout=subprocess.DEVNULL)
    d = load_npy(os.path.join(folder, "sine-euler"))
    assert np.max(np.abs(d["vorticity"][0] - runs["h5"]["vorticity"][-1])) < 1e-13
    print("--init: a run's .h5 continues from its last snapshot")
EOF
echo "PASS: lpi run data (.npy$( [ "$have_h5" = 1 ] && echo ', HDF5')) and --init"
