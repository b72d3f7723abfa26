"""integrate(t_eval, dt): the states at the requested times; copies and
pickles through the checkpoint; errors as OSError/ValueError; complex grids."""
import copy
import os
import pickle
import tempfile
import unittest

import liepoisson as lp
from support import np, as_list

DT = 0.01


def body(method="yoshida-6"):
    b = lp.RigidBody(1.0, 2.0, 3.0)
    b.method = method
    b.state = [1.0, 0.5, -0.3]
    return b


class TestIntegrate(unittest.TestCase):
    def test_states_at_the_requested_times(self):
        times = [0.0, 0.25, 0.25, 1.0, 3.7]
        with body() as b, body() as ref:
            sol = b.integrate(times, DT, energy=True, casimirs=True)
            self.assertEqual(len(sol), len(times))
            if np is not None:
                self.assertEqual(sol.y.shape, (5, 3))
                self.assertEqual(sol.casimirs.shape, (5, 1))
                self.assertEqual(sol.t.shape, (5,))
            # Independently: plain steps of the same counts on a second system.
            done = 0
            for i, t in enumerate(times):
                n = round(t / DT)
                ref.step(DT, n - done)
                done = n
                self.assertEqual(as_list(sol.y[i]), as_list(ref.state))
                self.assertEqual(float(sol.t[i]), ref.time)
                self.assertAlmostEqual(float(sol.t[i]), t, delta=1e-12)
                self.assertEqual(float(sol.energy[i]), ref.energy())
                self.assertEqual(as_list(sol.casimirs[i]), as_list(ref.casimirs()))
            self.assertEqual(b.time, ref.time)
            c = [as_list(row)[0] for row in sol.casimirs]
            self.assertLess(max(c) - min(c), 1e-14 * c[0])
            self.assertIsNone(b.integrate([3.7], DT).energy)

    def test_backwards_and_from_a_later_start(self):
        with body() as b:
            b.step(DT, 100)
            sol = b.integrate([1.0, 0.5, 0.0], -DT)
            self.assertAlmostEqual(float(sol.t[-1]), 0.0, delta=1e-12)
            # Time-symmetric method: back to the start to round-off.
            self.assertLess(max(abs(x - y) for x, y in zip(as_list(sol.y[-1]), [1.0, 0.5, -0.3])), 1e-12)

    def test_times_off_the_grid_or_behind_are_refused(self):
        with body() as b:
            # [0.5, 1e30]: a step count past int64, refused before stepping to 0.5.
            for bad, dt in (([0.0, 0.105], DT), ([0.5, 0.2], DT), ([-0.01], DT), ([0.1], -DT),
                            ([float("nan")], DT), ([float("inf")], DT), ([0.5, 1e30], DT)):
                with self.assertRaises(ValueError, msg=repr(bad)):
                    b.integrate(bad, dt)
                self.assertEqual(b.time, 0.0)  # nothing stepped
            # And the message says why (NaN and a count past a double were
            # reported as times lying behind).
            for bad, dt, why in (([float("nan")], DT, "not finite"), ([float("-inf")], -DT, "not finite"),
                                 ([1e300], 1e-10, "more than a step count holds"),
                                 ([-1e300], 1e-10, "lies behind the current time")):
                with self.assertRaises(ValueError, msg=repr(bad)) as caught:
                    b.integrate(bad, dt)
                self.assertIn(why, str(caught.exception))
                self.assertEqual(b.time, 0.0)
            for dt in (0.0, float("nan")):
                with self.assertRaises(ValueError):
                    b.integrate([1.0], dt)
            with self.assertRaises(TypeError):
                b.integrate(["1.0"], DT)
            self.assertEqual(as_list(b.state), [1.0, 0.5, -0.3])
            # A time a long run's rounding away from the grid is still whole.
            sol = b.integrate([0.1 * 3], 0.1)
            self.assertEqual(round(b.time / 0.1), 3)
            self.assertEqual(len(sol), 1)


class TestCopies(unittest.TestCase):
    def check_independent_and_continuing(self, original, duplicate):
        self.assertIsInstance(duplicate, type(original))
        self.assertIsNot(duplicate._handle, original._handle)
        self.assertEqual(duplicate.method, original.method)
        self.assertEqual((as_list(duplicate.state), duplicate.time), (as_list(original.state), original.time))
        duplicate.step(DT, 7)
        self.assertNotEqual(duplicate.time, original.time)  # stepping the copy leaves the original
        original.step(DT, 7)
        self.assertEqual((as_list(duplicate.state), duplicate.time), (as_list(original.state), original.time))

    def test_copy_deepcopy_pickle(self):
        for make in (copy.copy, copy.deepcopy, lambda s: pickle.loads(pickle.dumps(s))):
            with body("kahan-li-6") as b:
                b.split = "axes"
                b.step(DT, 13)
                with make(b) as dup:
                    self.assertEqual(dup.split, "axes")
                    self.check_independent_and_continuing(b, dup)
        with lp.Pendulum() as p:
            p.set_composition([0.5, 0.5])
            p.state = [0.6, -0.8, 1.2]
            p.step(DT, 5)
            with copy.copy(p) as dup:
                self.assertEqual(dup.method, "custom")
                self.check_independent_and_continuing(p, dup)

    def test_generic_systems_refuse(self):
        g = lp.Generic(3, [(0, 1, 2, -1.0), (0, 2, 1, 1.0), (1, 2, 0, -1.0)])
        for make in (copy.copy, copy.deepcopy, pickle.dumps):
            with self.assertRaises(TypeError) as cm:
                make(g)
            self.assertIn("callables", str(cm.exception))
        with self.assertRaises(TypeError):
            copy.copy(lp.Moments())

    def test_closed_systems_refuse(self):
        b = body()
        b.close()
        with self.assertRaises(ValueError):
            copy.copy(b)


class TestErrorKinds(unittest.TestCase):
    def test_io_and_format_errors(self):
        with body() as b, tempfile.TemporaryDirectory() as d:
            with self.assertRaises(OSError) as cm:
                b.save(os.path.join(d, "absent", "run.lpi"))
            self.assertIsInstance(cm.exception, lp.FileError)
            with self.assertRaises(OSError):
                lp.load(os.path.join(d, "absent.lpi"))
            path = os.path.join(d, "bad.lpi")
            with open(path, "wb") as f:
                f.write(b"LPI" + bytes(100))
            with self.assertRaises(ValueError) as cm:
                lp.load(path)
            self.assertIsInstance(cm.exception, lp.FormatError)
            data = b.save_bytes()
            with self.assertRaises(ValueError):
                lp.load_bytes(data[:-1])

    def test_a_complex_grid_is_refused(self):
        try:
            s = lp.SineEuler(5)
        except lp.UnsupportedError:
            self.skipTest("library built without FFTW")
        with s:
            s.grid = [[float(a - b) for b in range(5)] for a in range(5)]
            before = [as_list(r) for r in s.grid]
            bad = [[complex(a, 1) for _ in range(5)] for a in range(5)]
            with self.assertRaises(TypeError):
                s.grid = bad
            for shape_wrong in ([[0.0] * 25], [[0.0] * 4 + [0.0] * 6] + [[0.0] * 5] * 3):
                with self.assertRaises(ValueError):  # the right count in the wrong shape (SizeError)
                    s.grid = shape_wrong
                with self.assertRaises(ValueError):
                    s.modes = [[complex(v) for v in row] for row in shape_wrong]
            if np is not None:
                with self.assertRaises(TypeError):
                    s.grid = np.array(bad)
                with self.assertRaises(TypeError):
                    s.grid = np.zeros((5, 5), dtype=np.complex128)  # even with zero imaginary parts
                with self.assertRaises(ValueError):
                    s.grid = np.zeros((1, 25))
            self.assertEqual([as_list(r) for r in s.grid], before)


if __name__ == "__main__":
    unittest.main()
