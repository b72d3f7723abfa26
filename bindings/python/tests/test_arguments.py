"""Every argument is checked before ctypes converts it (ctypes wraps integers
silently and ends C strings at a NUL), statuses map to exception classes by
value, and Ctrl-C during a long step is never lost."""
import os
import signal
import tempfile
import threading
import time
import unittest

import liepoisson as lp
from support import np, as_list, rigid_body, SO3


def sine_euler_or_skip(test, N=5):
    try:
        return lp.SineEuler(N)
    except lp.UnsupportedError:
        test.skipTest("built without FFTW")


class TestIntegerRanges(unittest.TestCase):
    def assert_unchanged(self, system, state, t):
        self.assertEqual(as_list(system.state), state)
        self.assertEqual(system.time, t)

    def test_step_counts(self):
        with rigid_body() as b:
            b.step(0.01, 3)
            state, t = as_list(b.state), b.time
            for n in (2 ** 64 + 5, 2 ** 63, -2 ** 63 - 1, 10 ** 30):
                with self.assertRaises(OverflowError):
                    b.step(0.01, n)
                self.assert_unchanged(b, state, t)
            for n in (2.9, 5.0, "5", True, None):
                with self.assertRaises(TypeError):
                    b.step(0.01, n)
                self.assert_unchanged(b, state, t)
            with self.assertRaises(lp.InvalidArgumentError):  # in range, refused by the library
                b.step(0.01, -3)
            self.assert_unchanged(b, state, t)

    def test_step_sizes(self):
        with rigid_body() as b:
            state = as_list(b.state)
            for dt in (float("nan"), float("inf"), -float("inf")):
                with self.assertRaises(lp.LiePoissonError):
                    b.step(dt, 2)
                self.assert_unchanged(b, state, 0.0)
            for dt in ("0.01", b"0.01", None, 1j):
                with self.assertRaises(TypeError):
                    b.step(dt, 2)
            with self.assertRaises(OverflowError):
                b.step(10 ** 400, 1)  # an int too large for a double
            self.assert_unchanged(b, state, 0.0)

    def test_numpy_integers_are_integers(self):
        if np is None:
            self.skipTest("numpy not available")
        with rigid_body() as a, rigid_body() as b:
            a.step(0.01, np.int64(7))
            b.step(0.01, 7)
            self.assertEqual(as_list(a.state), as_list(b.state))
            with self.assertRaises(TypeError):
                a.step(0.01, np.float64(7.0))

    def test_numpy_bools_are_not_integers(self):
        # np.bool_ has an __index__ (deprecated), so it would pass as 0 or 1.
        if np is None:
            self.skipTest("numpy not available")
        with rigid_body() as b:
            for call in (lambda: b.step(0.01, np.bool_(True)),
                         lambda: b.step(0.01, 2, observer=lambda *a: None, every=np.bool_(True))):
                with self.assertRaises(TypeError):
                    call()
            self.assertEqual(b.time, 0.0)
            with self.assertRaises(TypeError):
                b.threads = np.bool_(True)
        g = lp.Generic(3, SO3)
        with self.assertRaises(TypeError):
            g.add_piece([np.bool_(False)], lambda x: [x[0]], lambda x: 0.5 * x[0] ** 2)
        with self.assertRaises(lp.InvalidArgumentError):  # no piece was added
            g.step(0.01, 1)

    def test_numpy_times_are_not_numbers(self):
        # numpy registers timedelta64 as an integer type; float() of it fails.
        if np is None:
            self.skipTest("numpy not available")
        with rigid_body() as b:
            before = as_list(b.state)
            for what, call in (("dt", lambda: b.step(np.timedelta64(1, "ms"), 1)),
                               ("state", lambda: b.set_state([np.timedelta64(1, "s"), 0.0, 0.0]))):
                with self.assertRaisesRegex(TypeError, "%s.* must be a real number, not timedelta64" % what):
                    call()
            self.assertEqual((as_list(b.state), b.time), (before, 0.0))

    def test_sizes_of_systems(self):
        for N in (2 ** 32 + 5, 2 ** 31, -2 ** 31 - 1):
            with self.assertRaises(OverflowError):
                lp.SineEuler(N)
        with self.assertRaises(TypeError):
            lp.SineEuler(5.0)
        for dim in (2 ** 64 + 3, -1):
            with self.assertRaises(OverflowError):
                lp.Generic(dim, SO3)
        for bad in ((2 ** 32, 1, 2, -1.0), (0, -2 ** 31 - 1, 2, 1.0), (0, 1, 2 ** 31, 1.0)):
            with self.assertRaises(OverflowError):
                lp.Generic(3, [bad])
        with self.assertRaises(TypeError):
            lp.Generic(3, [(0, 1, 2, "1.0")])

    def test_threads_and_implicit_options(self):
        with rigid_body() as b:
            for n in (2 ** 32 + 1, 2 ** 31, -2 ** 31 - 1):
                with self.assertRaises(OverflowError):
                    b.threads = n
                self.assertEqual(b.threads, 1)
            with self.assertRaises(TypeError):
                b.threads = 1.5
            with self.assertRaises(OverflowError):
                b.set_implicit_options(1e-13, 2 ** 32 + 100)
            with self.assertRaises(TypeError):
                b.set_implicit_options("1e-13", 100)

    def test_piece_indices(self):
        g = lp.Generic(3, SO3)
        for idx in ([2 ** 32], [0, 2 ** 31], [-2 ** 31 - 1]):
            with self.assertRaises(OverflowError):
                g.add_piece(idx, lambda x: [0.0] * len(x), lambda x: 0.0)
        with self.assertRaises(TypeError):
            g.add_piece([0.0], lambda x: [0.0], lambda x: 0.0)
        g.add_piece([0], lambda x: [x[0]], lambda x: 0.5 * x[0] ** 2)  # the handle still works
        g.state = [1.0, 0.5, -0.3]
        g.step(0.01, 2)
        g.close()

    def test_sine_euler_counts(self):
        with self.assertRaises(OverflowError):
            lp.SineEuler(2 ** 32 + 5)
        s = sine_euler_or_skip(self)
        with s:
            with self.assertRaises(OverflowError):
                s.casimir_traces(2 ** 32 + 2)
            with self.assertRaises(OverflowError):
                s.fft_floor(2 ** 64 + 1)
            with self.assertRaises(TypeError):
                s.fft_floor(1.5)
            self.assertEqual(len(s.casimir_traces(2)), 2)

    def test_status_functions(self):
        with self.assertRaises(OverflowError):
            lp.status_name(2 ** 40 - 3)  # ctypes would have asked for -3
        with self.assertRaises(OverflowError):
            lp.status_message(2 ** 32 - 3)
        self.assertEqual(lp.status_name(-3), "LPI_ERR_SIZE")


class TestArraysAndStrings(unittest.TestCase):
    def test_states_must_be_real_vectors(self):
        with rigid_body() as b:
            state = as_list(b.state)
            # [True, 0.5, 0.3]: numpy took the bool among floats as 1.0.
            for bad in (["1", "2", "3"], [1.0, None, 2.0], [1j, 0.0, 0.0], [True, 0.5, 0.3],
                        (0.5, False, 0.3)):
                with self.assertRaises(TypeError):
                    b.state = bad
                self.assertEqual(as_list(b.state), state)

    def test_callbacks_must_be_callable(self):
        # Refused when added: they used to fail only at the first step.
        g = lp.Generic(3, SO3)
        for gradient, energy in ((None, lambda x: 0.0), (lambda x: [0.0], None), (42, 42)):
            with self.assertRaises(TypeError):
                g.add_piece([0], gradient, energy)
        with self.assertRaises(TypeError):
            g.add_casimir(None)
        g.close()
        m = lp.Moments()
        with self.assertRaises(TypeError):
            m.add_product_piece(None, 42)
        with self.assertRaises(TypeError):
            m.add_product_piece(lambda u: u, "dh")
        m.close()

    def test_arrays_are_sequences_in_both_modes(self):
        # Iterating these gives byte values, keys, characters or an arbitrary
        # order: refused alike with and without numpy, wherever an array is taken.
        not_arrays = (b"abc", bytearray(b"abc"), {1.0: "a", 2.0: "b", 3.0: "c"}, {1.0, 2.0, 3.0},
                      frozenset((1.0, 2.0, 3.0)), "123", iter([1.0, 2.0, 3.0]), 5.0, None)
        with rigid_body() as b:
            state, t = as_list(b.state), b.time
            for bad in not_arrays:
                for refused in (lambda: setattr(b, "state", bad), lambda: b.set_composition(bad),
                                lambda: b.integrate(bad, 0.5)):
                    with self.assertRaises(TypeError, msg=repr(bad)):
                        refused()
                self.assertEqual(as_list(b.state), state)
                self.assertEqual(b.time, t)
            for bad in ([b"\x01", 0.0, 0.0], [{1.0}, 0.0, 0.0], [{1.0: 0}, 0.0, 0.0]):
                with self.assertRaises(TypeError, msg=repr(bad)):
                    b.state = bad
            for bad in ([[1.0, 0.5, -0.3]], [[1.0], 0.5, -0.3]):
                with self.assertRaises(ValueError, msg=repr(bad)):
                    b.state = bad
            b.state = [2 ** 70, 0, 0]  # a real number, exact as a double
            self.assertEqual(as_list(b.state), [2.0 ** 70, 0.0, 0.0])
            with self.assertRaises(OverflowError):
                b.state = [2 ** 1100, 0, 0]
            self.assertEqual(as_list(b.state), [2.0 ** 70, 0.0, 0.0])
            sol = b.integrate((b.time, b.time + 0.5), 0.5)
            self.assertEqual(len(sol), 2)
        g = lp.Generic(3, SO3)
        for bad in (b"\x00", {0}, "0"):
            with self.assertRaises(TypeError, msg=repr(bad)):
                g.add_piece(bad, lambda x: [x[0]], lambda x: 0.0)
            with self.assertRaises(TypeError, msg=repr(bad)):
                g.poisson_rank(bad)
        for bad in ([b"\x00\x01\x02\x01"], {(0, 1, 2, -1.0)}, [{0: 0, 1: 1, 2: 2, -1.0: 3}]):
            with self.assertRaises(TypeError, msg=repr(bad)):
                lp.Generic(3, bad)
        self.assertEqual(g.casimir_count, 0)

    def test_sine_euler_arrays_in_both_modes(self):
        s = sine_euler_or_skip(self, 3)
        with s:
            before = [as_list(row) for row in s.grid]
            lam = [[0.0, 1.0, 1.0], [1.0, 0.5, 0.5], [1.0, 0.5, 0.5]]
            for bad in ([b"\x01\x02\x03"] * 3, [{1.0, 2.0, 3.0}] * 3, b"abc", {0: [1.0] * 3},
                        [["1", "2", "3"]] * 3):
                with self.assertRaises(TypeError, msg=repr(bad)):
                    s.grid = bad
                with self.assertRaises(TypeError, msg=repr(bad)):
                    s.modes = bad
                with self.assertRaises(TypeError, msg=repr(bad)):
                    s.set_hamiltonian(bad)
                with self.assertRaises(TypeError, msg=repr(bad)):
                    s.set_hamiltonian(lam, bad)
            for bad in ([[[1.0]] * 3] * 3, [1.0] * 9):
                with self.assertRaises(lp.SizeError, msg=repr(bad)):
                    s.grid = bad
            self.assertEqual([as_list(row) for row in s.grid], before)
            s.grid = [[2 ** 70, 0, 0], [0, 0, 0], [0, 0, 0]]
            self.assertAlmostEqual(as_list(s.grid[0])[0] / 2.0 ** 70, 1.0, places=12)

    def test_numpy_arrays_of_other_kinds(self):
        if np is None:
            self.skipTest("numpy not available")
        with rigid_body() as b:
            b.state = np.array([1.0, 0.5, -0.25], dtype=np.float32)  # exact in float32
            self.assertEqual(as_list(b.state), [1.0, 0.5, -0.25])
            b.state = np.arange(9.0)[::3]  # non-contiguous: copied
            self.assertEqual(as_list(b.state), [0.0, 3.0, 6.0])
            with self.assertRaises(TypeError):
                b.state = np.array([1.0, 0.5, -0.3], dtype=np.complex128)  # would drop the imaginary parts
            with self.assertRaises(TypeError):
                b.state = np.array(["1", "2", "3"])
            with self.assertRaises(TypeError):
                b.state = np.array([True, False, True])
            with self.assertRaises(ValueError):
                b.state = np.ones((3, 1))
            self.assertEqual(as_list(b.state), [0.0, 3.0, 6.0])
        s = sine_euler_or_skip(self)
        with s:
            with self.assertRaises(TypeError):
                s.modes = np.full((5, 5), "x")
            grid = s.grid
            s.grid = np.asfortranarray(grid)  # another memory order, same values
            self.assertEqual(s.grid.tolist(), grid.tolist())

    def test_strings_are_whole(self):
        with rigid_body() as b, tempfile.TemporaryDirectory() as d:
            with self.assertRaises(ValueError):
                b.method = "leapfrog\0yoshida-6"  # C would read "leapfrog"
            with self.assertRaises(TypeError):
                b.method = b"leapfrog"
            self.assertEqual(b.method, "leapfrog")
            with self.assertRaises(ValueError):
                b.save(os.path.join(d, "a.lpi\0b"))
            self.assertEqual(os.listdir(d), [])
            with self.assertRaises(ValueError):
                lp.load(os.path.join(d, "a.lpi\0b"))
        with self.assertRaises(TypeError):
            lp.load_bytes(5)  # bytes(5) would be five zero bytes
        with self.assertRaises(TypeError):
            lp.fftw_wisdom_import_string(b"(fftw-3.3.10 fftw_wisdom)")
        with self.assertRaises(ValueError):
            lp.fftw_wisdom_import_string("(fftw\0")


class TestStatuses(unittest.TestCase):
    def test_newer_statuses_map_by_value(self):
        self.assertEqual(lp.BusyError.status, -13)
        self.assertTrue(issubclass(lp.BusyError, lp.LiePoissonError))
        self.assertEqual(lp.OverflowStatusError.status, -14)
        self.assertTrue(issubclass(lp.OverflowStatusError, OverflowError))
        self.assertTrue(issubclass(lp.OverflowStatusError, lp.LiePoissonError))
        self.assertEqual(lp.status_name(-13), "LPI_ERR_BUSY")
        self.assertEqual(lp.status_name(-14), "LPI_ERR_OVERFLOW")
        self.assertEqual(lp.LPI_STOPPED, 1)
        self.assertEqual(lp.STATUS["LPI_STOPPED"], 1)
        self.assertFalse(any(cls.status > 0 for cls in lp._by_status.values()))  # STOPPED is no error
        self.assertTrue(issubclass(lp.FileError, OSError))
        self.assertTrue(issubclass(lp.FormatError, ValueError))
        for status, cls in ((-13, lp.BusyError), (-14, lp.OverflowStatusError), (-11, lp.FileError)):
            with self.assertRaises(cls) as cm:
                lp._raise(status, "detail")
            self.assertEqual(cm.exception.status, status)
            self.assertEqual(cm.exception.message, "detail")

    def test_unknown_statuses_still_raise(self):
        with self.assertRaises(lp.LiePoissonError) as cm:
            lp._raise(-63, "from a newer library")
        self.assertIs(type(cm.exception), lp.LiePoissonError)
        self.assertEqual(cm.exception.status_name, "LPI_UNKNOWN_STATUS")

    def test_file_and_format_errors(self):
        with self.assertRaises(lp.FileError):
            lp.load("/nonexistent/dir/run.lpi")
        with self.assertRaises(lp.FormatError):
            lp.load_bytes(b"not a checkpoint")


def steps_for(seconds):
    """A step count that takes about `seconds` for rigid_body() here (only
    sizes the run; nothing is asserted about time)."""
    with rigid_body() as b:
        n, elapsed = 1000, 0.0
        while elapsed < 0.05:
            n *= 4
            start = time.perf_counter()
            b.step(1e-3, n)
            elapsed = time.perf_counter() - start
        return int(n * seconds / elapsed)


@unittest.skipIf(threading.current_thread() is not threading.main_thread(), "signals need the main thread")
class TestInterrupt(unittest.TestCase):
    def interrupt_soon(self):
        timer = threading.Timer(0.1, os.kill, (os.getpid(), signal.SIGINT))
        timer.start()
        self.addCleanup(timer.join)

    def test_sigint_during_a_long_step_is_not_lost(self):
        n = steps_for(1.0)
        with rigid_body() as b:
            self.interrupt_soon()
            with self.assertRaises(KeyboardInterrupt):
                b.step(1e-3, n)
            done = round(b.time / 1e-3)
            self.assertEqual(b.time, 1e-3 * done)
            # Stopped early, holding exactly the state of a call of `done` steps.
            self.assertLess(done, n)
            with rigid_body() as ref:
                ref.step(1e-3, done)
                self.assertEqual(as_list(b.state), as_list(ref.state))
            b.step(1e-3, 10)  # and the handle goes on

    def test_observing_keeps_the_bits(self):
        saved = lp._OBSERVE_SECONDS
        lp._OBSERVE_SECONDS = 1e-9  # observe nearly every step
        self.addCleanup(setattr, lp, "_OBSERVE_SECONDS", saved)
        with rigid_body() as a, rigid_body() as b:
            a.method = b.method = "yoshida-6"
            a.step(0.01, 1001)  # observed
            self.assertEqual(lp.lib.lpi_step(b._h(), 0.01, 1001), 0)  # one plain call
            self.assertEqual(as_list(a.state), as_list(b.state))
            self.assertEqual(a.time, b.time)

    def test_sigint_before_a_failing_step_is_not_lost(self):
        # Ctrl-C, then a callback fails before the next look for it (in the
        # same call: the handler is held back while the library is inside
        # one): the failure is the context of the KeyboardInterrupt, not its end.
        calls = [0]

        def gradient(x):
            calls[0] += 1
            if calls[0] == 100:
                os.kill(os.getpid(), signal.SIGINT)
                raise RuntimeError("model failure")
            return [x[0]]

        g = lp.Generic(3, SO3)
        g.add_piece([0], gradient, lambda x: 0.5 * x[0] ** 2)
        g.add_piece([1], lambda x: [x[0] / 2], lambda x: x[0] ** 2 / 4)
        g.state = [1.0, 0.5, -0.3]
        with self.assertRaises(KeyboardInterrupt) as caught:
            g.step(1e-4, 10 ** 7)
        self.assertIsInstance(caught.exception.__context__, lp.CallbackError)
        self.assertEqual(g.time, 0.0)  # the failed step rolled back

    def test_sigint_stops_steps_that_call_python_soon(self):
        # The first call has no measured speed: its guess must not take
        # flows that call Python for as fast as the library's own.
        def gradient(x):
            time.sleep(2e-5)
            return [x[0]]

        g = lp.Generic(3, SO3)
        g.add_piece([0], gradient, lambda x: 0.5 * x[0] ** 2)
        g.add_piece([1], lambda x: [x[0] / 2], lambda x: x[0] ** 2 / 4)
        g.state = [1.0, 0.5, -0.3]
        self.interrupt_soon()
        with self.assertRaises(KeyboardInterrupt):
            g.step(1e-4, 10 ** 8)
        # Each step sleeps 2e-5 s at least, so at most 5000 steps come before
        # the SIGINT at 0.1 s, and it is looked for every 1250 steps (0.05 s
        # at the guessed 2e-5 s a flow). A guess of 1e-7 s a flow and entry
        # looked first after 83333.
        self.assertLess(round(g.time / 1e-4), 10000)

    def test_a_handler_that_does_not_raise_lets_the_step_finish(self):
        calls = []
        previous = signal.signal(signal.SIGINT, lambda signum, frame: calls.append(signum))
        self.addCleanup(signal.signal, signal.SIGINT, previous)
        n = steps_for(0.5)
        with rigid_body() as b:
            self.interrupt_soon()
            b.step(1e-3, n)
            self.assertEqual(round(b.time / 1e-3), n)
        self.assertEqual(calls, [signal.SIGINT])


if __name__ == "__main__":
    unittest.main()
