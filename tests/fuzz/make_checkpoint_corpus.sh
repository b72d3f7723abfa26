#!/bin/sh
# Regenerates tests/fuzz/corpus_checkpoint: a small checkpoint of every kind
# that can be saved, written by the lpi CLI of a build (default ./build), and
# through the Python binding what the CLI does not set (a custom composition,
# another split, implicit settings). The files NAME_v1 are kept from format
# version 1 (no time carry), which the library still reads.
#   tests/fuzz/make_checkpoint_corpus.sh [BUILD_DIR]
set -eu
root="$(cd "$(dirname "$0")/../.." && pwd)"
build="${1:-$root/build}"
lpi="$build/lpi"
corpus="$root/tests/fuzz/corpus_checkpoint"
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$corpus"
save() {  # NAME SCENE [lpi run options]
    name="$1" scene="$2"
    shift 2
    "$lpi" run "$scene" --out "$scratch" --checkpoint "$corpus/$name" "$@" >/dev/null
}
save rigid_body_yoshida6 rigid-body --method yoshida-6 --dt 0.05 --steps 20
save rigid_body_implicit_midpoint rigid-body --method implicit-midpoint --dt 0.05 --steps 20
save pendulum_leapfrog pendulum --dt 0.1 --steps 30
save pendulum_triple_jump8 pendulum --method triple-jump-8 --dt 0.1 --steps 5
save sine_euler3_leapfrog sine-euler --N 3 --snapshots 0 --dt 0.05 --steps 10
save sine_euler5_rk4 sine-euler --N 5 --snapshots 0 --method rk4 --dt 0.05 --steps 10
LIEPOISSON_LIBRARY="$build/libliepoisson.so" PYTHONPATH="$root/bindings/python" \
    python3 - "$corpus" <<'PY'
import sys
import liepoisson as lp

corpus = sys.argv[1]
body = lp.RigidBody(1.0, 2.0, 3.5)
body.set_state([0.3, 1.1, -0.7])
body.split = "axes"
g = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
body.set_composition([g, 1.0 - 2.0 * g, g])
body.step(0.05, 20)
body.save(corpus + "/rigid_body_axes_custom")
pendulum = lp.Pendulum()
pendulum.set_state([0.6, -0.8, 1.3])
pendulum.set_method("implicit-midpoint")
pendulum.set_implicit_options(1e-8, 7)
pendulum.step(0.05, 10)
pendulum.save(corpus + "/pendulum_implicit_loose")
PY
ls -l "$corpus"
