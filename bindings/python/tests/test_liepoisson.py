"""Tests of the Python binding (unittest). Run with LIEPOISSON_LIBRARY set to
the built library; LIEPOISSON_NO_NUMPY=1 exercises the plain-list paths."""
import ctypes.util
import gc
import math
import os
import random
import tempfile
import threading
import unittest
import unittest.mock
import weakref

import liepoisson as lp
from support import np, as_list, SO3

TJ4 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))  # Yoshida's triple jump, outer weight
INERTIA = (1.0, 2.0, 3.0)


def distance(a, b):
    return max(abs(x - y) for x, y in zip(as_list(a), as_list(b)))


def generic_rigid_body():
    g = lp.Generic(3, SO3)
    for k in range(3):
        I = INERTIA[k]
        g.add_piece([k], lambda x, I=I: [x[0] / I], lambda x, I=I: 0.5 * x[0] * x[0] / I)
    g.add_casimir(lambda x: sum(v * v for v in x))
    return g


class TestModule(unittest.TestCase):
    def test_version_and_methods(self):
        self.assertRegex(lp.version, r"^\d+\.\d+\.\d+$")
        major, minor, patch = (int(p) for p in lp.version.split("."))
        self.assertEqual(lp.version_number, major * 10000 + minor * 100 + patch)
        by_name = {m.name: m for m in lp.methods()}
        self.assertEqual(by_name["leapfrog"].order, 2)
        self.assertTrue(by_name["leapfrog"].is_poisson)
        self.assertFalse(by_name["rk4"].is_poisson)
        self.assertGreaterEqual(by_name["leapfrog"].stages, 1)
        self.assertTrue(by_name["leapfrog"].reference)

    def test_statuses_come_from_the_library(self):
        self.assertEqual(lp.LPI_OK, 0)
        self.assertEqual(lp.LPI_ERR_SIZE, -3)
        self.assertEqual(lp.status_name(-3), "LPI_ERR_SIZE")
        self.assertEqual(lp.SizeError.status, -3)
        self.assertEqual(lp.CallbackError.status, lp.STATUS["LPI_ERR_CALLBACK"])
        self.assertEqual(lp.status_name(12345), "LPI_UNKNOWN_STATUS")

    def test_errors_pickle_and_copy(self):
        # As an error raised in a multiprocessing worker must, to reach the caller.
        import copy
        import pickle
        errors = [lp.LiePoissonError(-3, "m")]
        for name in lp.STATUS:
            if lp.STATUS[name] < 0:
                cls = lp._by_status.get(lp.STATUS[name], lp.LiePoissonError)
                errors.append(cls(lp.STATUS[name], "the message of " + name))
        for e in errors:
            for twin in (pickle.loads(pickle.dumps(e)), copy.copy(e), copy.deepcopy(e)):
                self.assertIs(type(twin), type(e))
                self.assertEqual((twin.status, twin.status_name, twin.message, str(twin)),
                                 (e.status, e.status_name, e.message, str(e)))

    def test_a_library_without_the_bindings_functions_is_refused_at_import(self):
        import subprocess
        import sys
        libm = ctypes.util.find_library("m")
        if not libm:
            self.skipTest("no libm to stand for an older library")
        env = dict(os.environ, LIEPOISSON_LIBRARY=libm)
        run = subprocess.run([sys.executable, "-c", "import liepoisson"], env=env,
                             capture_output=True, text=True)
        self.assertNotEqual(run.returncode, 0)
        self.assertIn("ImportError", run.stderr)
        self.assertIn("lacks lpi_", run.stderr)
        self.assertIn("LIEPOISSON_LIBRARY", run.stderr)

    def test_numpy_mode(self):
        if os.environ.get("LIEPOISSON_NO_NUMPY"):
            self.assertFalse(lp.HAVE_NUMPY)
        if os.environ.get("LIEPOISSON_REQUIRE_NUMPY"):
            self.assertTrue(lp.HAVE_NUMPY)
        with lp.Pendulum() as p:
            p.state = [0.6, -0.8, 1.2]
            s = p.state
            if lp.HAVE_NUMPY:
                self.assertIsInstance(s, np.ndarray)
                self.assertEqual(s.dtype, np.float64)
            else:
                self.assertIsInstance(s, list)


class TestCheckpoints(unittest.TestCase):
    def test_resume_bit_for_bit(self):
        with lp.RigidBody(*INERTIA) as body, tempfile.TemporaryDirectory() as d:
            body.method = "kahan-li-6"
            body.state = [1.0, 0.5, -0.3]
            body.step(0.01, 37)
            path = os.path.join(d, "run.lpi")
            body.save(path)
            data = body.save_bytes()
            body.step(0.01, 50)
            for copy in (lp.load(path), lp.load_bytes(data)):
                with copy:
                    self.assertIsInstance(copy, lp.RigidBody)
                    self.assertEqual(copy.kind, "rigid-body")
                    self.assertEqual(copy.method, "kahan-li-6")
                    self.assertEqual(copy.split, body.split)
                    copy.step(0.01, 50)
                    self.assertEqual(as_list(copy.state), as_list(body.state))
                    self.assertEqual(copy.time, body.time)

    def test_bad_checkpoints(self):
        with self.assertRaises(lp.LiePoissonError) as caught:
            lp.load_bytes(b"not a checkpoint")
        self.assertEqual(caught.exception.status_name, "LPI_ERR_FORMAT")
        with self.assertRaises(lp.LiePoissonError) as caught:
            lp.load("/nonexistent/dir/run.lpi")
        self.assertEqual(caught.exception.status_name, "LPI_ERR_IO")
        g = generic_rigid_body()
        with self.assertRaises(lp.LiePoissonError) as caught:
            g.save_bytes()
        self.assertEqual(caught.exception.status_name, "LPI_ERR_UNSUPPORTED")
        g.close()


class TestRigidBody(unittest.TestCase):
    def test_casimir_kept_by_splitting_not_by_rk4(self):
        drifts = {}
        for method in ("leapfrog", "triple-jump-4", "rk4"):
            with lp.RigidBody(*INERTIA) as b:
                b.method = method
                self.assertEqual(b.method, method)
                b.state = [1.0, 0.5, -0.3]
                c0 = b.casimirs()[0]
                b.step(0.1, 2000)
                self.assertAlmostEqual(b.time, 200.0, places=9)
                drifts[method] = abs(b.casimirs()[0] - c0) / c0
        self.assertLess(drifts["leapfrog"], 1e-13)
        self.assertLess(drifts["triple-jump-4"], 1e-13)
        self.assertGreater(drifts["rk4"], 1e-8)  # the baseline is no Poisson map

    def test_error_raises_with_status_message_and_state_unchanged(self):
        b = lp.RigidBody(*INERTIA)
        b.state = [1.0, 0.5, -0.3]
        b.step(0.01, 10)
        before, t0 = as_list(b.state), b.time
        with self.assertRaises(lp.SizeError) as cm:
            b.set_state([1.0, 2.0])
        e = cm.exception
        self.assertIsInstance(e, lp.LiePoissonError)
        self.assertIsInstance(e, ValueError)
        self.assertEqual(e.status, -3)
        self.assertEqual(e.status_name, "LPI_ERR_SIZE")
        self.assertIn("lpi_set_state", e.message)
        self.assertIn(e.message, str(e))
        self.assertEqual(b.last_error, e.message)
        for bad in (lambda: b.step(float("nan"), 1), lambda: b.step(0.0, 1)):
            with self.assertRaises(lp.LiePoissonError) as cm:
                bad()
            self.assertIn("lpi_step", cm.exception.message)
        with self.assertRaises(lp.NonFiniteError):
            b.step(float("inf"))
        with self.assertRaises(lp.InvalidArgumentError) as cm:
            b.method = "no-such-method"
        self.assertIn("no-such-method", cm.exception.message)
        self.assertEqual(b.method, "leapfrog")
        self.assertEqual(as_list(b.state), before)  # bit for bit
        self.assertEqual(b.time, t0)
        b.close()

    def test_failed_create_reports_the_thread_message(self):
        with self.assertRaises(lp.InvalidArgumentError) as cm:
            lp.RigidBody(-1.0, 1.0, 1.0)
        self.assertIn("lpi_rigid_body_create", cm.exception.message)

    def test_exact_solution_and_splits(self):
        with lp.RigidBody(*INERTIA) as b:
            self.assertEqual(b.split, "casimir-shift")  # the default, read back
            self.assertEqual(b.kind, "rigid-body")
            b.split = "axes"
            self.assertEqual(b.split, "axes")
            b.method = "suzuki-6"
            b.state = [1.0, 0.5, -0.3]
            exact = b.exact(1.0)
            self.assertEqual(as_list(b.state), [1.0, 0.5, -0.3])
            b.step(0.01, 100)
            self.assertLess(distance(b.state, exact), 1e-9)

    def test_composition_and_flows(self):
        with lp.RigidBody(*INERTIA) as b:
            b.set_composition([TJ4, 1.0 - 2.0 * TJ4, TJ4])
            self.assertEqual(b.method, "custom")
            self.assertGreater(b.flows_per_step(), 0)
            with self.assertRaises(lp.InvalidArgumentError):
                b.set_composition([0.5, 0.6])
            self.assertEqual(b.method, "custom")

    def test_implicit_options_and_threads(self):
        with lp.RigidBody(*INERTIA) as b:
            b.method = "implicit-midpoint"
            b.state = [1.0, 0.5, -0.3]
            b.set_implicit_options(1e-15, 1)
            with self.assertRaises(lp.NoConvergenceError):
                b.step(0.1, 5)
            self.assertEqual(as_list(b.state), [1.0, 0.5, -0.3])
            b.set_implicit_options()
            b.step(0.1, 5)
            b.threads = 1
            with self.assertRaises(lp.UnsupportedError):
                b.threads = 2
            self.assertEqual(b.threads, 1)

    def test_lifetime(self):
        b = lp.RigidBody(*INERTIA)
        with b:
            pass
        self.assertTrue(b.closed)
        b.close()  # idempotent
        with self.assertRaises(ValueError):
            b.step(0.1)
        fin = lp.Pendulum()._finalizer
        gc.collect()
        self.assertFalse(fin.alive)  # the finaliser released the handle

    def test_another_thread_is_refused_while_a_call_runs(self):
        # ctypes lets go of the GIL during a call: without the binding's own
        # claim a second thread reached the library on the same handle (two
        # threads alternating set_method and step crashed the interpreter).
        # Held inside an observer, so the first thread is surely mid-call.
        b = lp.RigidBody(*INERTIA)
        b.state = [1.0, 0.5, -0.3]
        ref = lp.RigidBody(*INERTIA)
        ref.state = [1.0, 0.5, -0.3]
        ref.step(0.1, 4)
        inside, go = threading.Event(), threading.Event()

        def observer(system, step, t):
            inside.set()
            go.wait(10)

        worker = threading.Thread(target=b.step, args=(0.1, 4), kwargs={"observer": observer, "every": 2})
        worker.start()
        try:
            self.assertTrue(inside.wait(10))
            attempts = [lambda: b.set_method("yoshida-6"), lambda: b.set_state([0.0, 1.0, 0.0]),
                        lambda: b.step(0.1), b.close, lambda: b.time, lambda: b.method,
                        lambda: b.get_state(), b.energy, b.save_bytes, lambda: b.integrate([1.0], 0.1)]
            for attempt in attempts:
                with self.assertRaises(lp.BusyError) as caught:
                    attempt()
                self.assertIn("another thread", str(caught.exception))
            self.assertIn("in use by another thread", repr(b))
        finally:
            go.set()
            worker.join(10)
        self.assertFalse(b.closed)
        self.assertEqual(b.method, "leapfrog")
        self.assertEqual(b.time, ref.time)
        self.assertEqual(as_list(b.state), as_list(ref.state))
        b.close()
        ref.close()

    def test_system_in_a_cycle_through_its_callbacks_is_freed(self):
        class Model:
            """Owns the system and gives it its own methods: a reference
            cycle through the ctypes callbacks, which gc must collect."""
            def __init__(self):
                self.sys = lp.Generic(3, SO3)
                self.sys.add_piece([0], self.grad, self.energy)
                self.sys.add_casimir(self.casimir)

            def grad(self, x):
                return [x[0]]

            def energy(self, x):
                return 0.5 * x[0] ** 2

            def casimir(self, x):
                return sum(v * v for v in x)

        gc.collect()
        destroyed = []
        real_destroy = lp.lib.lpi_destroy

        def spy(handle):
            status = real_destroy(handle)
            destroyed.append((handle.value, status))
            return status

        with unittest.mock.patch.object(lp.lib, "lpi_destroy", spy):
            m = Model()
            m.sys.state = [1.0, 0.5, -0.3]
            m.sys.step(0.1, 3)
            handle = m.sys._handle.value
            model, system = weakref.ref(m), weakref.ref(m.sys)
            del m
            gc.collect()
            self.assertIsNone(system())
            self.assertIsNone(model())
            self.assertEqual([st for h, st in destroyed if h == handle], [lp.LPI_OK])
            # close() lets go of the callbacks: the owner goes without gc
            m = Model()
            model = weakref.ref(m)
            with m.sys as g:
                g.state = [1.0, 0.5, -0.3]
                self.assertEqual(len(g.casimirs()), 1)
            del m
            self.assertIsNone(model())
            self.assertTrue(g.closed)


class TestGeneric(unittest.TestCase):
    def test_python_callbacks_match_the_built_in(self):
        g = generic_rigid_body()
        gc.collect()  # the lambdas live only inside g
        b = lp.RigidBody(*INERTIA)
        b.split = "axes"
        self.assertEqual(g.poisson_rank([1.0, 0.5, -0.3]), 2)
        for method in ("lie-trotter", "leapfrog", "triple-jump-4", "rk4"):
            g.method = b.method = method
            g.state = b.state = [1.0, 0.5, -0.3]
            worst = 0.0
            for _ in range(10):
                g.step(0.05, 100)
                b.step(0.05, 100)
                worst = max(worst, distance(g.state, b.state))
            self.assertLess(worst, 5e-13, method)
        self.assertAlmostEqual(g.energy(), b.energy(), delta=1e-14)
        self.assertEqual(g.casimir_count, 1)
        self.assertAlmostEqual(g.casimirs()[0], b.casimirs()[0], delta=1e-14)

    def test_raising_callback_fails_cleanly(self):
        calls = {"n": 0, "fail_after": 25}

        def grad(x):
            calls["n"] += 1
            if calls["n"] > calls["fail_after"]:
                raise RuntimeError("boom in gradient")
            return [x[0] / 2.0]

        g = lp.Generic(3, SO3)
        g.add_piece([0], lambda x: [x[0]], lambda x: 0.5 * x[0] ** 2)
        g.add_piece([1], grad, lambda x: 0.25 * x[0] ** 2)
        g.add_piece([2], lambda x: [x[0] / 3.0], lambda x: x[0] ** 2 / 6.0)
        g.state = [1.0, 0.5, -0.3]
        g.step(0.1, 3)
        before, t0 = as_list(g.state), g.time
        with self.assertRaises(lp.CallbackError) as cm:
            g.step(0.1, 100)
        e = cm.exception
        self.assertEqual(e.status, lp.LPI_ERR_CALLBACK)
        self.assertEqual(e.status_name, "LPI_ERR_CALLBACK")
        self.assertIn("lpi_step", e.message)
        self.assertIsInstance(e.__cause__, RuntimeError)
        self.assertEqual(str(e.__cause__), "boom in gradient")
        self.assertEqual(as_list(g.state), before)
        self.assertEqual(g.time, t0)
        calls["fail_after"] = 10 ** 9  # the system is still usable
        g.step(0.1, 10)
        self.assertAlmostEqual(g.time, t0 + 1.0, places=12)

    def test_callback_cannot_close_or_change_its_own_system(self):
        g = lp.Generic(3, SO3)
        seen = []

        def grad(x):
            for intrusion in (g.close, lambda: setattr(g, "method", "rk4"),
                              lambda: setattr(g, "state", [0.0, 0.0, 1.0])):
                try:
                    intrusion()
                except lp.BusyError as e:
                    seen.append(e.status)
            return [x[0]]

        g.add_piece([0], grad, lambda x: 0.5 * x[0] ** 2)
        g.state = [1.0, 0.5, -0.3]
        g.step(0.1, 2)
        self.assertEqual(seen, [lp.LPI_ERR_BUSY] * len(seen))
        self.assertGreaterEqual(len(seen), 3)
        self.assertFalse(g.closed)
        self.assertEqual(g.method, "leapfrog")
        self.assertAlmostEqual(g.time, 0.2, places=14)
        g.close()
        self.assertTrue(g.closed)

    def test_bad_callback_results(self):
        g = lp.Generic(3, SO3)
        g.add_piece([0], lambda x: [1.0, 2.0], lambda x: 0.0)  # wrong length
        g.state = [1.0, 0.5, -0.3]
        with self.assertRaises(lp.CallbackError) as cm:
            g.step(0.1)
        self.assertIsInstance(cm.exception.__cause__, ValueError)
        g2 = lp.Generic(3, SO3)
        g2.add_casimir(lambda x: 1 / 0)
        with self.assertRaises(lp.CallbackError) as cm:
            g2.casimirs()
        self.assertIsInstance(cm.exception.__cause__, ZeroDivisionError)
        g3 = lp.Generic(3, SO3)
        g3.add_piece([1], lambda x: [float("nan")], lambda x: 0.0)
        g3.state = [1.0, 0.5, -0.3]
        with self.assertRaises(lp.LiePoissonError):
            g3.step(0.1)
        self.assertEqual(as_list(g3.state), [1.0, 0.5, -0.3])

    def test_callback_results_must_be_numbers(self):
        # float() would take "5", b"5" and True; the binding's own check refuses them
        def fails(make, call):
            g = make()
            with self.assertRaises(lp.CallbackError) as cm:
                call(g)
            self.assertIsInstance(cm.exception.__cause__, TypeError)

        def generic(grad=lambda x: [x[0]], energy=lambda x: 0.5 * x[0] ** 2, casimir=None):
            def make():
                g = lp.Generic(3, SO3)
                g.add_piece([0], grad, energy)
                if casimir is not None:
                    g.add_casimir(casimir)
                g.state = [1.0, 0.5, -0.3]
                return g
            return make

        for bad in ("5", b"5", {0: 1.0}, {1.0}, True, [True], ["5"], None):
            fails(generic(grad=lambda x, bad=bad: bad), lambda g: g.step(0.1))
        for bad in ("2.5", b"2", True, 1j, [1.0], None):
            fails(generic(energy=lambda x, bad=bad: bad), lambda g: g.energy())
        for bad in ("7", False):
            fails(generic(casimir=lambda x, bad=bad: bad), lambda g: g.casimirs())

        def moments(h, dh):
            def make():
                m = lp.Moments()
                m.add_product_piece(h, dh)
                m.state = [1.0, 0.2, 1.0, 3.0, 0.1, 1.0, 0.1, 3.0]
                return m
            return make

        fails(moments(lambda u: True, lambda u: 0.5), lambda m: m.energy())
        fails(moments(lambda u: 0.5 * u, lambda u: "0.5"), lambda m: m.step(0.1))
        # tuples and numpy numbers are fine
        g = generic(grad=lambda x: (x[0],), energy=lambda x: x[0] ** 2 / 2)()
        g.step(0.1)
        self.assertEqual(g.energy(), as_list(g.state)[0] ** 2 / 2)

    def test_not_abelian_and_bad_brackets(self):
        g = lp.Generic(3, SO3)
        with self.assertRaises(lp.NotAbelianError) as cm:
            g.add_piece([0, 1], lambda x: [0.0, 0.0], lambda x: 0.0)
        self.assertIn("lpi_add_piece", cm.exception.message)
        with self.assertRaises(lp.InvalidArgumentError):
            lp.Generic(3, [(0, 1, 7, 1.0)])
        with self.assertRaises(ValueError):
            lp.Generic(3, [(0, 1, 2)])

    def test_moments_keep_their_casimirs(self):
        m = lp.Moments()
        self.assertEqual(m.casimir_count, 2)
        # H = <p^2>/2 + <q^2>/2 + 0.01 <q^4> + 0.02 u + 0.01 u^2, u = <q^2><p^2>
        m.add_piece([0, 3], lambda x: [0.5, 0.01], lambda x: 0.5 * x[0] + 0.01 * x[1])
        m.add_piece([2], lambda x: [0.5], lambda x: 0.5 * x[0])
        m.add_product_piece(lambda u: 0.02 * u + 0.01 * u * u, lambda u: 0.02 + 0.02 * u)
        m.method = "triple-jump-4"
        # moments of a Gaussian with <q^2> = 1, <p^2> = 2, <qp> = 0.3
        a, b, c = 1.0, 0.3, 2.0
        m.state = [a, b, c, 3 * a * a, 3 * a * b, a * c + 2 * b * b, 3 * b * c, 3 * c * c]
        c0 = as_list(m.casimirs())
        m.step(0.01, 2000)
        c1 = as_list(m.casimirs())
        for x0, x1 in zip(c0, c1):
            self.assertLess(abs(x1 - x0), 1e-11 * max(1.0, abs(x0)))
        self.assertEqual(m.poisson_rank([1.0, 0.3, 2.0, 3.3, 0.7, 2.1, 1.9, 12.5]), 6)


class TestSineEuler(unittest.TestCase):
    N = 7

    def setUp(self):
        try:
            self.s = lp.SineEuler(self.N)
        except lp.UnsupportedError as e:
            self.assertIn("FFTW", e.message)
            self.skipTest("library built without FFTW")

    def tearDown(self):
        if hasattr(self, "s"):
            self.s.close()

    def random_grid(self):
        rng = random.Random(4)
        N = self.N
        w = [[rng.uniform(-1, 1) for _ in range(N)] for _ in range(N)]
        return np.array(w) if np is not None else w

    def test_size_and_bad_n(self):
        self.assertEqual(self.s.N, self.N)
        with self.assertRaises(lp.InvalidArgumentError):
            lp.SineEuler(8)

    def test_modes_round_trip(self):
        s, N = self.s, self.N
        w = self.random_grid()
        s.grid = w
        self.assertLess(distance(sum(map(as_list, s.grid), []), sum(map(as_list, w), [])), 1e-13)
        modes = s.modes
        if np is not None:
            self.assertEqual(modes.shape, (N, N))
            self.assertEqual(modes.dtype, np.complex128)
        # Hermitian: w_{-m} = conj(w_m)
        for a in range(N):
            for b in range(N):
                self.assertAlmostEqual(modes[a][b], modes[(-a) % N][(-b) % N].conjugate(), delta=1e-14)
        s.modes = modes
        back = s.modes
        flat = lambda z: [v for row in z for x in row for v in (x.real, x.imag)]
        self.assertEqual(flat(back), flat(modes))

    def test_non_hermitian_modes_refused_state_unchanged(self):
        s, N = self.s, self.N
        s.grid = self.random_grid()
        before = s.modes
        bad = [[complex(v) for v in row] for row in before]
        bad[1][2] += 0.5j
        with self.assertRaises(lp.InvalidArgumentError) as cm:
            s.modes = bad
        self.assertIn("lpi_sine_euler_set_modes", cm.exception.message)
        self.assertEqual([list(r) for r in s.modes], [list(r) for r in before])
        with self.assertRaises(lp.SizeError):
            s.modes = [[0j] * N] * (N - 1)

    def test_casimirs_kept(self):
        s = self.s
        s.grid = self.random_grid()
        t0 = as_list(s.casimir_traces(4))
        e0, h0 = s.enstrophy(), s.energy()
        s.step(0.01, 50)
        t1 = as_list(s.casimir_traces(4))
        for a, b in zip(t0, t1):
            self.assertLess(abs(a - b), 1e-12 * max(1.0, abs(a)))
        self.assertLess(abs(s.enstrophy() - e0), 1e-12 * e0)
        self.assertLess(abs(s.energy() - h0), 1e-3 * h0)
        with self.assertRaises(lp.InvalidArgumentError):
            s.casimir_traces(0)
        sec, count = s.fft_floor(2)
        self.assertGreater(count, 0)
        self.assertGreaterEqual(sec, 0.0)
        self.assertEqual(s.planning, "estimate")
        s.planning = "measure"
        self.assertEqual(s.planning, "measure")
        with self.assertRaises(lp.InvalidArgumentError):
            s.set_planning("exhaustive")
        self.assertEqual(s.planning, "measure")

    def test_hamiltonian_stream_and_spectrum(self):
        s, N = self.s, self.N
        s.grid = self.random_grid()
        c = lambda a: a - N if a > N // 2 else a
        norm2 = [[c(a) ** 2 + c(b) ** 2 for b in range(N)] for a in range(N)]
        sqg = [[1.0 / norm2[a][b] ** 0.5 if norm2[a][b] else 0.0 for b in range(N)] for a in range(N)]
        f = [[0j] * N for _ in range(N)]
        f[1][2], f[N - 1][N - 2] = 0.3 + 0.1j, 0.3 - 0.1j
        s.set_hamiltonian(sqg, f)
        modes = s.modes
        expected = sum(0.5 * sqg[a][b] * abs(modes[a][b]) ** 2 + (f[a][b].conjugate() * modes[a][b]).real
                       for a in range(N) for b in range(N))
        self.assertLess(abs(s.energy() - expected), 1e-13)
        self.assertEqual(s.last_error, "")
        energy, enstrophy = s.spectrum()
        self.assertEqual(s.last_error, "")  # its query of the shell count is no failure
        self.assertEqual(len(energy), int(((N - 1) // 2) * 2 ** 0.5 + 0.5))
        self.assertLess(abs(sum(as_list(energy)) - s.energy()), 1e-13)
        self.assertLess(abs(sum(as_list(enstrophy)) + 0.5 * modes[0][0].real ** 2 - s.enstrophy()), 1e-13)
        psi = s.stream_function()
        self.assertEqual(len(psi), N)
        energy_before = s.energy()
        bad = [row[:] for row in sqg]
        bad[0][1] += 1.0  # not symmetric
        with self.assertRaises(lp.InvalidArgumentError) as cm:
            s.set_hamiltonian(bad)
        self.assertIn("lpi_sine_euler_set_hamiltonian", cm.exception.message)
        self.assertEqual(s.energy(), energy_before)
        with self.assertRaises(lp.SizeError):
            s.set_hamiltonian([[1.0] * N] * (N - 1))
        # Rows of different lengths: SizeError in both modes (numpy's own
        # ValueError reached the caller).
        with self.assertRaises(lp.SizeError):
            s.grid = [[0.0] * N] * (N - 1) + [[0.0] * (N - 1)]

    def test_wisdom(self):
        text = lp.fftw_wisdom_export_string()
        self.assertIn("fftw", text)
        # Wisdom that another thread adds between the query of the length and
        # the copy (the wisdom is the process's): the copy is made again, not
        # refused as a buffer too small.
        export = lp.lib.lpi_fftw_wisdom_export_string
        planned = []

        def export_after_planning(buf, size, length):
            if buf is not None and not planned:
                with lp.SineEuler(43) as other:
                    other.planning = "measure"
                planned.append(other)
            return export(buf, size, length)

        with unittest.mock.patch.object(lp.lib, "lpi_fftw_wisdom_export_string", export_after_planning):
            grown = lp.fftw_wisdom_export_string()
        self.assertTrue(planned)
        self.assertGreater(len(grown), len(text))
        self.assertEqual(grown, lp.fftw_wisdom_export_string())
        lp.fftw_wisdom_import_string(text)
        with self.assertRaises(lp.InvalidArgumentError):
            lp.fftw_wisdom_import_string("not wisdom")
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "wisdom")
            lp.fftw_wisdom_export_file(path)
            lp.fftw_wisdom_import_file(path)
            with self.assertRaises(lp.LiePoissonError) as cm:
                lp.fftw_wisdom_import_file(os.path.join(d, "absent"))
            self.assertIn("absent", cm.exception.message)


@unittest.skipUnless(lp.HAVE_NUMPY, "numpy not available")
class TestNumpy(unittest.TestCase):
    def test_out_arrays_filled_in_place(self):
        with lp.RigidBody(*INERTIA) as b:
            b.state = np.array([1.0, 0.5, -0.3])
            out = np.zeros(3)
            self.assertIs(b.get_state(out=out), out)
            self.assertEqual(out.tolist(), [1.0, 0.5, -0.3])
            with self.assertRaises(ValueError):
                b.get_state(out=np.zeros(3, dtype=np.float32))
            b.state = np.array([1, 2, 3], dtype=np.int64)  # converted
            self.assertEqual(b.state.tolist(), [1.0, 2.0, 3.0])
            b.state = np.array([9.0, 1.0, 2.0, 3.0])[1:]  # a view, still contiguous
            self.assertEqual(b.state.tolist(), [1.0, 2.0, 3.0])
            b.state = np.array([1.0, 0.0, 2.0, 0.0, 3.0])[::2]  # strided: copied
            self.assertEqual(b.state.tolist(), [1.0, 2.0, 3.0])

    def test_unaligned_arrays(self):
        # Doubles at an address C may not read them from (an odd offset into a
        # buffer, a field of a packed record) are copied on the way in, and
        # refused as out=: passed as they were, they reached C misaligned.
        raw = bytearray(8 * 9 + 1)
        values = np.frombuffer(raw, dtype=np.float64, count=9, offset=1)
        self.assertFalse(values.flags.aligned)
        values[:3] = [1.0, 0.5, -0.3]
        with lp.RigidBody(*INERTIA) as b:
            b.state = values[:3]
            self.assertEqual(b.state.tolist(), [1.0, 0.5, -0.3])
            with self.assertRaises(ValueError) as caught:
                b.get_state(out=values[3:6])
            self.assertIn("aligned", str(caught.exception))
        try:
            se = lp.SineEuler(3)
        except lp.UnsupportedError:
            return
        with se:
            grid = values.reshape(3, 3)
            grid[:] = np.arange(9.0).reshape(3, 3)
            se.grid = grid
            self.assertTrue(np.allclose(se.grid, grid, atol=1e-14))

    def test_masked_entries_are_refused(self):
        # A masked array is an ndarray: its entries under the mask reached C.
        with lp.RigidBody(*INERTIA) as b:
            b.state = [1.0, 0.5, -0.3]
            b.step(0.1, 3)
            before, t = b.state.tolist(), b.time
            with self.assertRaises(ValueError) as caught:
                b.state = np.ma.array([1.0, 2.0, 3.0], mask=[0, 1, 0])
            self.assertIn("masked", str(caught.exception))
            with self.assertRaises(ValueError):
                b.set_composition(np.ma.array([0.5, 0.5], mask=[1, 0]))
            self.assertEqual((b.state.tolist(), b.time, b.method), (before, t, "leapfrog"))
            b.state = np.ma.array([1.0, 2.0, 3.0], mask=[0, 0, 0])  # nothing masked: its data
            self.assertEqual(b.state.tolist(), [1.0, 2.0, 3.0])
        try:
            se = lp.SineEuler(3)
        except lp.UnsupportedError:
            return
        with se:
            grid = np.ma.array(np.ones((3, 3)), mask=np.eye(3))
            with self.assertRaises(ValueError):
                se.grid = grid
            self.assertEqual(se.grid.tolist(), np.zeros((3, 3)).tolist())

    def test_callbacks_get_arrays(self):
        seen = []
        g = lp.Generic(3, SO3)
        g.add_casimir(lambda x: seen.append(type(x)) or float(np.dot(x, x)))
        g.state = [1.0, 2.0, 2.0]
        self.assertEqual(g.casimirs().tolist(), [9.0])
        self.assertIs(seen[0], np.ndarray)


if __name__ == "__main__":
    unittest.main()
