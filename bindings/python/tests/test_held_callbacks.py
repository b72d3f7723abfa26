"""What C holds stays alive through any exception, SIGINT's handler never runs
inside a callback, and step()'s results and bookkeeping stay true when
interrupted or raced."""
import copy
import os
import pickle
import signal
import sys
import threading
import time
import unittest

import liepoisson as lp
from support import np, as_list, rigid_body, SO3

DT = 0.01
MAIN_ONLY = unittest.skipIf(threading.current_thread() is not threading.main_thread(),
                            "signals need the main thread")


def generic():
    g = lp.Generic(3, SO3)
    g.add_piece([0], lambda x: [x[0]], lambda x: 0.5 * x[0] ** 2)
    g.state = [1.0, 0.5, -0.3]
    return g


def interrupt_as_call_returns(test, name):
    """A KeyboardInterrupt where Python runs the handler of a SIGINT that
    came during the C call lpi_<name>: as _call's claim is let go, the call
    done. Deterministic, through a trace hook. (The claim's lock stays with
    this thread then, which re-enters it.)"""
    def tracer(frame, event, arg):
        if (event == "call" and frame.f_code.co_name == "__exit__"
                and type(frame.f_locals.get("self")) is lp._Claim
                and frame.f_back.f_code.co_name == "_call" and frame.f_back.f_locals.get("name") == name):
            sys.settrace(None)
            raise KeyboardInterrupt
    test.addCleanup(sys.settrace, None)
    sys.settrace(tracer)


class TestHeldCallbacks(unittest.TestCase):
    def test_a_piece_interrupted_as_it_is_added_is_kept(self):
        with generic() as g:
            interrupt_as_call_returns(self, "lpi_add_piece")
            with self.assertRaises(KeyboardInterrupt):
                g.add_piece([1], lambda x: [x[0] / 2], lambda x: x[0] ** 2 / 4)
            self.assertEqual(len(g._keep), 4)  # both pieces' gradient and energy: C holds them
            self.assertEqual(g.energy(), 0.5 + 0.0625)  # the new piece is called, alive
            g.step(DT, 5)

    def test_a_casimir_interrupted_as_it_is_added_is_kept(self):
        with generic() as g:
            interrupt_as_call_returns(self, "lpi_add_casimir")
            with self.assertRaises(KeyboardInterrupt):
                g.add_casimir(lambda x: x[0] ** 2 + x[1] ** 2 + x[2] ** 2)
            self.assertEqual(len(g._keep), 3)
            self.assertAlmostEqual(as_list(g.casimirs())[0], 1.34)

    def test_a_refused_piece_is_not_kept(self):
        with generic() as g:
            with self.assertRaises(lp.NotAbelianError):
                g.add_piece([0, 1], lambda x: [x[0], x[1]], lambda x: 0.0)
            self.assertEqual(len(g._keep), 2)

    def test_an_observer_interrupted_as_it_is_set_is_removed(self):
        calls = []
        with rigid_body() as b:
            interrupt_as_call_returns(self, "lpi_set_observer")
            with self.assertRaises(KeyboardInterrupt):
                b.step(DT, 5, observer=lambda *a: calls.append(a))
            self.assertEqual(b._keep, [])  # C let it go, and so did Python
            self.assertEqual(b.step(DT, 5), 5)  # no longer observed
            self.assertEqual(calls, [])

    def test_an_observer_refused_inside_a_callback_is_not_kept(self):
        nested = []

        def watch(system, step, t):
            try:
                system.step(DT, 2, observer=lambda *a: None)
            except lp.BusyError as e:
                nested.append(e)

        with rigid_body() as b:
            for _ in range(3):
                b.step(DT, 10, observer=watch, every=5)
            self.assertEqual(len(nested), 6)
            self.assertEqual(b._keep, [])  # neither the refused observers nor the outer ones
        with generic() as g:
            g.step(DT, 10, observer=watch, every=5)
            self.assertEqual(len(g._keep), 2)  # the piece's gradient and energy alone

    def test_only_a_create_function_makes_a_system(self):
        for name, args in (("lpi_destroy", ()), ("lpi_step", (0.1, 1)), ("lpi_set_method", (None,))):
            with self.assertRaisesRegex(ValueError, "create must be one of"):
                lp.System(name, *args)
        with lp.System("lpi_pendulum_create") as p:
            self.assertEqual(p.dim, 3)  # e(2)


@MAIN_ONLY
class TestSigintHeldBack(unittest.TestCase):
    def test_a_sigint_in_a_callback_waits_for_the_call(self):
        # Its handler ran inside the callback, where an exception can reach C
        # only as an undefined result; now the callback ends and the call
        # returns first.
        finished = []

        def energy(x):
            os.kill(os.getpid(), signal.SIGINT)
            finished.append(True)
            return 0.5 * x[0] ** 2

        g = lp.Generic(3, SO3)
        g.add_piece([0], lambda x: [x[0]], energy)
        g.state = [1.0, 0.5, -0.3]
        with self.assertRaises(KeyboardInterrupt):
            g.energy()
        self.assertEqual(finished, [True])
        self.assertIs(signal.getsignal(signal.SIGINT), signal.default_int_handler)

    def test_a_sigint_in_an_observer_stops_at_the_next_look(self):
        finished = []

        def watch(system, step, t):
            if step == 3:
                os.kill(os.getpid(), signal.SIGINT)
                finished.append(step)

        with rigid_body() as b, rigid_body() as ref:
            with self.assertRaises(KeyboardInterrupt):
                b.step(DT, 40, observer=watch)  # short: no SIGINT watch of its own
            self.assertEqual(finished, [3])
            ref.step(DT, 4)
            self.assertEqual((as_list(b.state), b.time), (as_list(ref.state), ref.time))

    def test_a_stop_no_observer_asked_for_counts_the_steps_done(self):
        # An observer that fails before its first line (where a handler
        # raising used to land) leaves ctypes an undefined result, which C
        # may take for a stop: the count is then the steps done, not nsteps.
        real = lp._lib.OBSERVER_FN

        def undefined_at_step_7(*fn):
            if not fn:
                return real()  # NULL, the removal
            return real(lambda h, step, t, user: 21845 if step == 7 else fn[0](h, step, t, user))

        self.addCleanup(setattr, lp._lib, "OBSERVER_FN", real)
        lp._lib.OBSERVER_FN = undefined_at_step_7
        with rigid_body() as b:
            self.assertEqual(b.step(DT, 40, observer=lambda *a: None), 7)
            self.assertEqual(round(b.time / DT), 7)


class TestStepBookkeeping(unittest.TestCase):
    def test_no_busy_error_after_the_steps_are_done(self):
        # Another thread takes the system whenever step() asks what a step
        # costs: it must ask under its own claim, never after letting go.
        with rigid_body() as b:
            attempted, release, held = threading.Event(), threading.Event(), []

            def take():
                held.append(b._lock.acquire(blocking=False))
                attempted.set()
                if held[-1]:
                    release.wait(5)
                    b._lock.release()

            cost_key = b._step_cost_key

            def contested_cost_key():
                attempted.clear()
                thread = threading.Thread(target=take)
                thread.start()
                attempted.wait(5)
                self.addCleanup(thread.join)
                return cost_key()

            b._step_cost_key = contested_cost_key
            self.addCleanup(release.set)
            self.assertEqual(b.step(DT, 1), 1)
            self.assertEqual(held, [False])
            release.set()
            self.assertEqual(b.time, DT)

    @MAIN_ONLY
    def test_the_first_long_call_looks_for_sigint_soon(self):
        # direct-eq5 costs N^3 a flow, 40 times the guess at N = 31 (which
        # had the first call look every 130 steps, 2 s): before any step was
        # timed, Ctrl-C still ends the call within a few steps.
        N = 31
        try:
            s = lp.SineEuler(N)
        except lp.UnsupportedError:
            self.skipTest("built without FFTW")
        with s:
            s.grid = [[((3 * a + 5 * b) % N) - 15.0 for b in range(N)] for a in range(N)]
            s.method = "direct-eq5"
            timer = threading.Timer(0.02, os.kill, (os.getpid(), signal.SIGINT))
            timer.start()
            self.addCleanup(timer.join)
            with self.assertRaises(KeyboardInterrupt):
                s.step(1e-4, 1000)
            self.assertLess(round(s.time / 1e-4), 20)


@unittest.skipIf(np is None, "numpy's 0-d arrays")
class TestZeroDimensionalArrays(unittest.TestCase):
    def test_real_scalars_as_zero_d_arrays(self):
        with lp.RigidBody(np.array(1.0), np.float32(2.0), np.array(3)) as b:
            b.state = [1.0, 0.5, -0.3]
            self.assertEqual(b.step(np.array(0.01), np.array(2)), 2)
            self.assertEqual(b.time, 0.02)
            for wrong in (np.array(True), np.array(0.01 + 0j), np.array("0.01"), np.array([0.01])):
                with self.assertRaises(TypeError):
                    b.step(wrong, 1)

    def test_a_callback_may_return_a_zero_d_array(self):
        g = lp.Generic(3, SO3)
        g.add_piece([0], lambda x: np.asarray(x), lambda x: np.asarray(0.5 * x[0] ** 2))
        g.add_casimir(lambda x: np.sum(np.asarray(x) ** 2))
        g.state = [1.0, 0.5, -0.3]
        self.assertEqual(g.energy(), 0.5)
        self.assertAlmostEqual(float(g.casimirs()[0]), 1.34)


class TestCopiesKeepPlanning(unittest.TestCase):
    def test_copies_plan_at_the_same_rigor(self):
        try:
            s = lp.SineEuler(7)
        except lp.UnsupportedError:
            self.skipTest("built without FFTW")
        with s:
            s.grid = [[((3 * a + 5 * b) % 7) - 3.0 for b in range(7)] for a in range(7)]
            s.planning = "measure"
            for twin in (copy.copy(s), copy.deepcopy(s), pickle.loads(pickle.dumps(s))):
                with twin:
                    self.assertEqual(twin.planning, "measure")
            # a pickle from before the planning was kept: the checkpoint's default
            with lp._from_checkpoint(s.save_bytes(), 1) as old:
                self.assertEqual(old.planning, "estimate")


if __name__ == "__main__":
    unittest.main()
