"""step(observer=..., every=...): what the observer sees, stopping, exceptions,
and Ctrl-C alongside."""
import os
import signal
import threading
import unittest

import liepoisson as lp
from support import np, as_list

DT = 0.01


def body(method="yoshida-6"):
    b = lp.RigidBody(1.0, 2.0, 3.0)
    b.method = method
    b.state = [1.0, 0.5, -0.3]
    return b


def reference_state(steps, method="yoshida-6"):
    """The state after one plain call of `steps` steps, on a separate system."""
    with body(method) as ref:
        ref.step(DT, steps)
        return as_list(ref.state), ref.time


class TestObserver(unittest.TestCase):
    def test_sees_every_kth_step_with_the_exact_state(self):
        seen = []

        def watch(system, step, t):
            seen.append((step, t, as_list(system.state), system.energy()))

        with body() as b:
            self.assertEqual(b.step(DT, 100, observer=watch, every=7), 100)
            self.assertEqual([s for s, _, _, _ in seen], list(range(7, 100, 7)))
            for step, t, state, _ in seen[::4]:
                self.assertEqual((state, t), reference_state(step))
            # Observing changed no bit of the run itself.
            self.assertEqual((as_list(b.state), b.time), reference_state(100))
            energies = [e for _, _, _, e in seen]
            self.assertLess(max(energies) - min(energies), 1e-6)

    def test_a_truthy_return_stops_the_run(self):
        with body() as b:
            done = b.step(DT, 1000, observer=lambda s, step, t: step >= 30, every=10)
            self.assertEqual(done, 30)
            self.assertEqual((as_list(b.state), b.time), reference_state(30))
            self.assertEqual(b.step(DT, 5), 5)  # and the system goes on

    def test_an_exception_stops_the_run_and_propagates(self):
        class Enough(Exception):
            pass

        def watch(system, step, t):
            if step == 12:
                raise Enough(step)

        with body() as b:
            with self.assertRaises(Enough):
                b.step(DT, 50, observer=watch, every=4)
            self.assertEqual((as_list(b.state), b.time), reference_state(12))
            # The observer is removed: a plain step is not observed.
            self.assertEqual(b.step(DT, 50), 50)

    def test_reads_allowed_changes_busy(self):
        outcomes = []

        def watch(system, step, t):
            outcomes.append(as_list(system.casimirs()))
            system.set_state([0.0, 0.0, 1.0])

        with body() as b:
            with self.assertRaises(lp.BusyError):
                b.step(DT, 10, observer=watch, every=5)
            self.assertEqual(len(outcomes), 1)
            self.assertEqual((as_list(b.state), b.time), reference_state(5))

    def test_generic_energy_from_an_observer(self):
        so3 = [(0, 1, 2, -1.0), (0, 2, 1, 1.0), (1, 2, 0, -1.0)]
        g = lp.Generic(3, so3)
        for k, inertia in enumerate((1.0, 2.0, 3.0)):
            g.add_piece([k], lambda x, I=inertia: [x[0] / I], lambda x, I=inertia: 0.5 * x[0] ** 2 / I)
        with g:
            g.state = [1.0, 0.5, -0.3]
            e0 = g.energy()
            energies = []
            g.step(DT, 20, observer=lambda s, step, t: energies.append(s.energy()), every=5)
            self.assertEqual(len(energies), 4)
            self.assertLess(max(abs(e - e0) for e in energies), 1e-6)

    def test_bad_arguments(self):
        with body() as b:
            with self.assertRaises(ValueError):
                b.step(DT, 10, observer=lambda *a: None, every=0)
            with self.assertRaises(TypeError):
                b.step(DT, 10, observer=lambda *a: None, every=2.0)
            with self.assertRaises(TypeError):
                b.step(DT, 10, observer="not callable")
            with self.assertRaises(OverflowError):
                b.step(DT, 10, observer=lambda *a: None, every=2 ** 63)
            self.assertEqual(b.time, 0.0)


class TestCadence(unittest.TestCase):
    def test_a_divisor_of_every_near_the_wanted_cadence(self):
        for every, wanted in ((1000, 300), (7, 100), (4096, 1000), (999, 10), (1000003, 1000), (10 ** 12, 777)):
            c = lp._dividing_cadence(every, wanted)
            self.assertEqual(every % c, 0, (every, wanted))
            self.assertTrue(c <= wanted or c == every, (every, wanted, c))
        self.assertEqual(lp._dividing_cadence(1000, 300), 250)
        self.assertEqual(lp._dividing_cadence(1000003, 1000), 1000003)  # prime: the observer's own


@unittest.skipIf(threading.current_thread() is not threading.main_thread(), "signals need the main thread")
class TestObserverWithCtrlC(unittest.TestCase):
    def test_ctrl_c_and_the_observer_together(self):
        saved = lp._OBSERVE_SECONDS
        lp._OBSERVE_SECONDS = 1e-9  # look for SIGINT at nearly every step
        self.addCleanup(setattr, lp, "_OBSERVE_SECONDS", saved)
        seen = []

        def watch(system, step, t):
            seen.append(step)
            if step == 21:
                os.kill(os.getpid(), signal.SIGINT)

        with body() as b:
            with self.assertRaises(KeyboardInterrupt):
                b.step(DT, 10 ** 6, observer=watch, every=7)
            done = round(b.time / DT)
            self.assertGreaterEqual(done, 21)
            self.assertLess(done, 10 ** 6)
            self.assertEqual(seen, list(range(7, done + 1, 7)))
            self.assertEqual((as_list(b.state), b.time), reference_state(done))


if __name__ == "__main__":
    unittest.main()
