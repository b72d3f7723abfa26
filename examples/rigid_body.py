#!/usr/bin/env python3
"""The free rigid body from Python: states at requested times (integrate), a
run watched and stopped by an observer, and a copy that continues the same
trajectory. Run with the package importable (make install, or pip install
bindings/python with LIEPOISSON_LIBRARY naming the library). Exits 0 when the
Casimir |m|^2 was kept to round-off and the states agree with the exact
solution."""
import copy
import sys

import liepoisson as lp


def main():
    body = lp.RigidBody(1.0, 2.0, 3.0)
    body.method = "triple-jump-4"
    body.state = [1.0, 0.5, -0.3]
    exact = [list(body.exact(t)) for t in (0.0, 2.5, 5.0, 7.5, 10.0)]

    # States, energy and Casimir at the requested times, fixed step 0.005.
    sol = body.integrate([0.0, 2.5, 5.0, 7.5, 10.0], 0.005, energy=True, casimirs=True)
    casimir = [row[0] for row in sol.casimirs]
    drift = max(casimir) - min(casimir)
    error = max(abs(a - b) for row, ref in zip(sol.y, exact) for a, b in zip(row, ref))
    for t, y, e in zip(sol.t, sol.y, sol.energy):
        print("t = %5.2f  m = (% .6f, % .6f, % .6f)  H = %.12f" % (t, y[0], y[1], y[2], e))
    print("Casimir drift %.1e, error against the exact solution %.1e" % (drift, error))

    # An observer: stop once m2 changes sign (reading the system is allowed).
    twin = copy.copy(body)  # an independent system, same state and time
    start = body.state[1]
    done = body.step(0.005, 10000, observer=lambda system, step, t: system.state[1] * start < 0, every=10)
    print("m2 changed sign by t = %.2f (%d of 10000 steps)" % (body.time, done))
    twin.step(0.005, done)  # the copy, stepped as far, holds the same bits
    same = list(twin.state) == list(body.state)
    print("the copy continued the same trajectory: %s" % same)

    ok = drift < 1e-14 * casimir[0] and error < 1e-9 and 0 < done < 10000 and same
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
