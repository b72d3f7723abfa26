"""liepoisson: explicit, Casimir-preserving integration of Lie-Poisson systems.

A ctypes binding of the C library libliepoisson (no compiled extension). Arrays
are numpy arrays when numpy is installed (set LIEPOISSON_NO_NUMPY=1 to turn that
off) and plain lists otherwise; inputs may be any sequence.

    import liepoisson as lp
    with lp.RigidBody(1.0, 2.0, 3.0) as body:
        body.method = "triple-jump-4"
        body.state = [1.0, 0.5, -0.3]
        body.step(0.01, 1000)
        print(body.time, body.energy(), body.casimirs())
"""
import collections
import ctypes
import numbers
import operator
import os
import signal
import threading
import time
import weakref
from ctypes import byref, c_double, c_int32, c_size_t

from . import _lib
from ._lib import lib

np = None
if not os.environ.get("LIEPOISSON_NO_NUMPY"):
    try:
        import numpy as np
    except ImportError:
        np = None

#: True when arrays are numpy arrays (numpy importable and not turned off).
HAVE_NUMPY = np is not None

__all__ = [
    "version", "version_number", "methods", "Method", "status_name", "status_message", "HAVE_NUMPY",
    "System", "RigidBody", "Pendulum", "Generic", "Moments", "SineEuler",
    "load", "load_bytes", "fftw_wisdom_import_file", "fftw_wisdom_export_file",
    "fftw_wisdom_import_string", "fftw_wisdom_export_string",
    "LiePoissonError",
]


def _text(raw):
    return raw.decode("utf-8", "replace") if raw is not None else None


# ---- arguments: every value checked before ctypes converts it -----------------
# ctypes wraps integers silently (2**64 + 5 becomes 5) and a C string ends at
# its first NUL; every call goes through these conversions instead.

_C_INTEGER_RANGES = {
    "int": (-2 ** 31, 2 ** 31 - 1),
    "int32": (-2 ** 31, 2 ** 31 - 1),
    "int64": (-2 ** 63, 2 ** 63 - 1),
    "size": (0, 2 ** (8 * ctypes.sizeof(c_size_t)) - 1),
}


def _integer(value, what, ctype):
    """value as an int that fits the C type ctype ("int32", "int64", "size"):
    TypeError for a non-integer (a float, a string, a bool), OverflowError
    outside the type's range."""
    if isinstance(value, bool):
        raise TypeError("%s must be an integer, not bool" % what)
    try:
        v = operator.index(value)
    except TypeError:
        raise TypeError("%s must be an integer, not %s" % (what, type(value).__name__)) from None
    lo, hi = _C_INTEGER_RANGES[ctype]
    if not lo <= v <= hi:
        raise OverflowError("%s = %d is out of range for the C type (%d .. %d)" % (what, v, lo, hi))
    return v


def _real(value, what):
    """value as a float: TypeError for anything but a real number (no strings)."""
    if isinstance(value, (bool, str, bytes)) or not isinstance(value, numbers.Real):
        raise TypeError("%s must be a real number, not %s" % (what, type(value).__name__))
    return float(value)


def _c_string(value, what):
    """A str as UTF-8 bytes for a C string: TypeError otherwise, ValueError
    for an embedded NUL (C would stop reading there)."""
    if not isinstance(value, str):
        raise TypeError("%s must be a str, not %s" % (what, type(value).__name__))
    if "\0" in value:
        raise ValueError("%s contains a NUL character" % what)
    return value.encode()


def _c_path(path):
    """A path (str, bytes or os.PathLike) as bytes for C, no embedded NUL."""
    raw = os.fsencode(path)
    if b"\0" in raw:
        raise ValueError("embedded null byte in path")
    return raw


#: The library's version, "MAJOR.MINOR.PATCH".
version = _text(lib.lpi_version_string())
__version__ = version
#: The same as one number, MAJOR * 10000 + MINOR * 100 + PATCH: compare this.
version_number = lib.lpi_version_number()


def status_name(status):
    """"LPI_ERR_SIZE" for -3, "LPI_UNKNOWN_STATUS" for a value that is no status."""
    status = _integer(status, "status", "int")
    name = _text(lib.lpi_status_name(status))
    if name == "LPI_UNKNOWN_STATUS" and status in _KNOWN_AHEAD:
        return _KNOWN_AHEAD[status][0]
    return name


def status_message(status):
    """The one-line description of a status code."""
    status = _integer(status, "status", "int")
    if status in _KNOWN_AHEAD and _text(lib.lpi_status_name(status)) == "LPI_UNKNOWN_STATUS":
        return _KNOWN_AHEAD[status][1]
    return _text(lib.lpi_status_message(status))


# ---- exceptions: one class per status, built from the library's own list ----

class LiePoissonError(Exception):
    """A liepoisson call failed. .status is the code (negative), .status_name
    its name ("LPI_ERR_SIZE") and .message the library's detailed message."""
    status = None

    def __init__(self, status, message):
        self.status = status
        self.status_name = status_name(status)
        self.message = message
        super().__init__("%s: %s" % (self.status_name, message))


# Python names and extra base classes per status name; a status the library
# grows later still raises LiePoissonError with its name and message.
_ERROR_CLASSES = {
    "LPI_ERR_NULL": ("NullArgumentError", (ValueError,)),
    "LPI_ERR_INVALID": ("InvalidArgumentError", (ValueError,)),
    "LPI_ERR_SIZE": ("SizeError", (ValueError,)),
    "LPI_ERR_NONFINITE": ("NonFiniteError", (ArithmeticError,)),
    "LPI_ERR_NOT_ABELIAN": ("NotAbelianError", (ValueError,)),
    "LPI_ERR_UNSUPPORTED": ("UnsupportedError", (NotImplementedError,)),
    "LPI_ERR_NO_MEMORY": ("OutOfMemoryError", (MemoryError,)),
    "LPI_ERR_INTERNAL": ("InternalError", ()),
    "LPI_ERR_CALLBACK": ("CallbackError", ()),
    "LPI_ERR_NO_CONVERGENCE": ("NoConvergenceError", (ArithmeticError,)),
    "LPI_ERR_IO": ("FileError", (OSError,)),
    "LPI_ERR_FORMAT": ("FormatError", (ValueError,)),
    "LPI_ERR_BUSY": ("BusyError", (RuntimeError,)),
    "LPI_ERR_OVERFLOW": ("OverflowStatusError", (OverflowError,)),
}

# Statuses of newer libraries, by value, so that their exception classes exist
# (and map) whatever library is loaded: value -> (name, message).
_KNOWN_AHEAD = {
    -13: ("LPI_ERR_BUSY", "the handle is inside one of its own callbacks"),
    -14: ("LPI_ERR_OVERFLOW", "a result of finite inputs overflows a double"),
    1: ("LPI_STOPPED", "the observer stopped the step loop (not an error)"),
}

#: Status codes by name, read from the library ({"LPI_OK": 0, "LPI_ERR_NULL": -1, ...}).
STATUS = {}
_by_status = {}


# How far the scan looks: statuses are small integers, errors negative and the
# few non-error results (LPI_STOPPED) positive; a gap does not end the scan.
_STATUS_SCAN = range(-64, 17)


def _scan_statuses():
    for code in _STATUS_SCAN:
        name = status_name(code)
        if name == "LPI_UNKNOWN_STATUS":
            continue
        STATUS[name] = code
        globals()[name] = code
        __all__.append(name)
        if code < 0:
            pyname, bases = _ERROR_CLASSES.get(name, (None, ()))
            if pyname:
                cls = type(pyname, (LiePoissonError,) + bases,
                           {"__doc__": "%s: %s." % (name, status_message(code)), "status": code,
                            "__module__": __name__})
                globals()[pyname] = cls
                __all__.append(pyname)
                _by_status[code] = cls


_scan_statuses()


def _raise(status, message, cause=None):
    cls = _by_status.get(status, LiePoissonError)
    err = cls(status, message)
    if cause is not None:
        raise err from cause
    raise err


def _check_free(status):
    """Checks a call that has no handle (its message is the thread's)."""
    if status != 0:
        _raise(status, _text(lib.lpi_last_error(None)))


# ---- Ctrl-C during a long step ---------------------------------------------------
# ctypes releases the GIL during a foreign call, and Python's SIGINT handler
# only sets a flag that the main thread acts on once it is back in Python: a
# SIGINT during lpi_step is not lost, but waits for the whole call. A step()
# long enough to matter is therefore observed (lpi_set_observer, when the
# library has it) about every _OBSERVE_SECONDS; observing does not change the
# trajectory to the bit, so the cadence may follow the measured speed.
_HAVE_OBSERVER = "lpi_set_observer" not in _lib.MISSING
_OBSERVE_SECONDS = 0.05


# ---- methods ----------------------------------------------------------------

Method = collections.namedtuple("Method", "name order stages reference is_poisson")


def methods():
    """The registered methods, in the library's order."""
    out = []
    for i in range(lib.lpi_method_count()):
        out.append(Method(_text(lib.lpi_method_name(i)), lib.lpi_method_order(i),
                          lib.lpi_method_stages(i), _text(lib.lpi_method_reference(i)),
                          lib.lpi_method_is_poisson(i) == 1))
    return out


# ---- arrays in and out --------------------------------------------------------

def _real_array(values, what, kinds="iuf"):
    """values as a numpy array of real (or, with kinds "iufc", complex)
    numbers: TypeError for strings, objects, booleans and (unless allowed)
    complex numbers, which numpy would otherwise convert or truncate."""
    a = np.asarray(values)
    if a.dtype.kind not in kinds:
        raise TypeError("%s must be %s numbers, not an array of %s"
                        % (what, "complex" if "c" in kinds else "real", a.dtype))
    return a


def _doubles_in(values, what="values"):
    """(pointer, length, keep-alive) for a flat sequence of real numbers. A
    C-contiguous float64 numpy vector is passed as it is (no copy); any other
    real array (float32, integers, a strided view) is copied."""
    if np is not None:
        a = values
        if not (isinstance(a, np.ndarray) and a.dtype == np.float64 and a.flags.c_contiguous):
            a = np.ascontiguousarray(_real_array(values, what), dtype=np.float64)
        if a.ndim != 1:
            raise ValueError("%s must be one-dimensional, not of shape %s" % (what, a.shape))
        return a.ctypes.data_as(_lib.c_double_p), a.size, a
    vals = [_real(v, what) for v in values]
    buf = (c_double * len(vals))(*vals)
    return buf, len(vals), buf


def _doubles_out(n, out=None):
    """(pointer, result-maker) for n output doubles; out, a C-contiguous float64
    numpy array of n elements, is filled in place."""
    if np is not None:
        if out is None:
            out = np.empty(n, dtype=np.float64)
        elif not (isinstance(out, np.ndarray) and out.dtype == np.float64
                  and out.flags.c_contiguous and out.flags.writeable and out.size == n):
            raise ValueError("out must be a writeable C-contiguous float64 array of %d elements" % n)
        return out.ctypes.data_as(_lib.c_double_p), (lambda: out)
    if out is not None:
        raise ValueError("out= needs numpy")
    buf = (c_double * n)()
    return buf, (lambda: list(buf))


def _int32s(values, what):
    vals = [_integer(v, what, "int32") for v in values]
    return (c_int32 * max(len(vals), 1))(*vals), len(vals)


def _callback_view(ptr, n):
    # A copy: the pointer is valid only during the callback.
    if np is not None:
        return np.ctypeslib.as_array(ptr, (n,)).copy() if n else np.empty(0)
    return ptr[:n]


# ---- systems ------------------------------------------------------------------

def _destroy(handle, keep):
    # keep holds the ctypes callbacks until the handle that calls them is gone.
    status = lib.lpi_destroy(handle)
    if status == 0:
        del keep[:]
    return status


class System:
    """A handle to one integrated system. Use a subclass to create one; close()
    (or a with block, or garbage collection) releases it."""

    def __init__(self, create, *args):
        handle = ctypes.c_void_p()
        _check_free(getattr(lib, create)(byref(handle), *args))
        self._handle = handle
        self._keep = []        # ctypes callbacks the library holds
        self._pending = []     # exception raised inside a callback during the current call
        self._threads = 1
        self._seconds_per_step = None  # measured by step(), for the SIGINT observer
        self._finalizer = weakref.finalize(self, _destroy, handle, self._keep)

    # lifetime
    def close(self):
        """Releases the handle now (idempotent).

        Raises
        ------
        BusyError
            When called from one of this system's own callbacks (a piece, a
            Casimir or an observer): the system stays open and unchanged.
        """
        if not self._finalizer.alive:
            return
        self._finalizer.detach()
        status = _destroy(self._handle, self._keep)
        if status != 0:
            self._finalizer = weakref.finalize(self, _destroy, self._handle, self._keep)
            _raise(status, _text(lib.lpi_last_error(self._handle)))

    @property
    def closed(self):
        return not self._finalizer.alive

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def _h(self):
        if not self._finalizer.alive:
            raise ValueError("operation on a closed liepoisson system")
        return self._handle

    def _call(self, name, *args):
        """Calls lpi_<name>(handle, *args), raises on a failed (negative)
        status and returns the status otherwise (LPI_OK, LPI_STOPPED)."""
        del self._pending[:]
        status = getattr(lib, name)(self._h(), *args)
        if status < 0:
            cause = self._pending[0] if self._pending else None
            del self._pending[:]
            if cause is not None and not isinstance(cause, Exception):
                raise cause  # KeyboardInterrupt, SystemExit: not ours to wrap
            _raise(status, _text(lib.lpi_last_error(self._handle)), cause)
        return status

    @property
    def last_error(self):
        """The message of the most recent failed call on this system ("" if none)."""
        return _text(lib.lpi_last_error(self._h()))

    @property
    def kind(self):
        """The system's kind: "rigid-body", "pendulum", "generic", "moments", "sine-euler"."""
        return _text(lib.lpi_kind(self._h()))

    # method and split
    @property
    def method(self):
        """The method's name ("leapfrog" until set; "custom" after set_composition;
        an alias set is reported by its name)."""
        return _text(lib.lpi_get_method(self._h()))

    @method.setter
    def method(self, name):
        self.set_method(name)

    def set_method(self, name):
        self._call("lpi_set_method", _c_string(name, "method"))

    @property
    def split(self):
        """The split's name (the system's default until set)."""
        return _text(lib.lpi_get_split(self._h()))

    @split.setter
    def split(self, name):
        self.set_split(name)

    def set_split(self, name):
        self._call("lpi_set_split", _c_string(name, "split"))

    def set_composition(self, gammas):
        """A symmetric composition of leapfrog with weights gammas (method "custom")."""
        ptr, n, _keep = _doubles_in(gammas, "gammas")
        self._call("lpi_set_composition", n, ptr)

    def flows_per_step(self):
        out = c_size_t()
        self._call("lpi_flows_per_step", byref(out))
        return out.value

    def set_implicit_options(self, tolerance=1e-13, max_iterations=100):
        self._call("lpi_set_implicit_options", _real(tolerance, "tolerance"),
                   _integer(max_iterations, "max_iterations", "int32"))

    @property
    def threads(self):
        return self._threads

    @threads.setter
    def threads(self, n):
        n = _integer(n, "threads", "int32")
        self._call("lpi_set_threads", n)
        self._threads = n

    # state
    @property
    def dim(self):
        return lib.lpi_dim(self._h())

    def __len__(self):
        return self.dim

    def get_state(self, out=None):
        n = self.dim
        ptr, result = _doubles_out(n, out)
        self._call("lpi_get_state", ptr, n)
        return result()

    def set_state(self, x):
        """Sets the state (length dim) and resets the time to 0."""
        ptr, n, _keep = _doubles_in(x, "state")
        self._call("lpi_set_state", ptr, n)

    state = property(get_state, set_state)

    @property
    def time(self):
        return lib.lpi_time(self._h())

    def step(self, dt, nsteps=1):
        """Advances nsteps steps of size dt. On failure the state is unchanged.

        Ctrl-C (SIGINT) during a long step: with a library that has
        lpi_set_observer, the step stops within about _OBSERVE_SECONDS and the
        SIGINT handler runs there (KeyboardInterrupt by default), the system
        holding exactly the state of a call of the steps done (see .time);
        otherwise the handler runs when the whole call returns. Either way the
        bits of a step that is not interrupted do not depend on timing."""
        dt = _real(dt, "dt")
        nsteps = _integer(nsteps, "nsteps", "int64")
        started = time.perf_counter()
        every = self._observation_interval(nsteps)
        if every:
            self._step_observing_sigint(dt, nsteps, every)
        else:
            self._call("lpi_step", dt, nsteps)
        if nsteps > 0:
            self._seconds_per_step = (time.perf_counter() - started) / nsteps

    def _observation_interval(self, nsteps):
        """Steps between looks for a SIGINT during step(), or 0 for none: the
        call is short, the library has no observer, this is not the main
        thread (only it runs signal handlers) or SIGINT has no Python handler."""
        if not _HAVE_OBSERVER or nsteps < 2 or threading.current_thread() is not threading.main_thread():
            return 0
        if not callable(signal.getsignal(signal.SIGINT)):
            return 0
        seconds = self._seconds_per_step
        if seconds is None:
            # Not measured yet: 1e-7 s per flow and state entry, more than any
            # system takes (an overestimate only makes the looks more frequent).
            flows = c_size_t(1)
            if lib.lpi_flows_per_step(self._h(), byref(flows)) != 0:
                flows.value = 1
            seconds = 1e-7 * max(flows.value, 1) * max(self.dim, 1)
        if seconds * nsteps < _OBSERVE_SECONDS:
            return 0
        return max(1, min(nsteps, int(_OBSERVE_SECONDS / max(seconds, 1e-12))))

    def _step_observing_sigint(self, dt, nsteps, every):
        # SIGINT only sets a flag during the call; the observer runs the
        # handler that was in place, and stops the step if that raised.
        received, raised = [], []
        previous = signal.getsignal(signal.SIGINT)

        def run_previous_handler():
            del received[:]
            previous(signal.SIGINT, None)

        def observe(sys, step, t, user):
            if not received:
                return 0
            try:
                run_previous_handler()
            except BaseException as e:  # noqa: B902 - must not cross into C
                raised.append(e)
                return 1
            return 0

        observer = _lib.OBSERVER_FN(observe)
        signal.signal(signal.SIGINT, lambda signum, frame: received.append(signum))
        try:
            self._call("lpi_set_observer", every, observer, None)
            try:
                self._call("lpi_step", dt, nsteps)
            finally:
                lib.lpi_set_observer(self._handle, 0, _lib.OBSERVER_FN(), None)  # NULL: removed
        finally:
            signal.signal(signal.SIGINT, previous)
        if raised:
            raise raised[0]
        if received:  # arrived after the last observation
            run_previous_handler()

    def energy(self):
        out = c_double()
        self._call("lpi_energy", byref(out))
        return out.value

    @property
    def casimir_count(self):
        return lib.lpi_casimir_count(self._h())

    def casimirs(self, out=None):
        n = self.casimir_count
        ptr, result = _doubles_out(n, out)
        self._call("lpi_casimirs", ptr, n)
        return result()

    # checkpoints
    def save(self, path):
        """Writes a checkpoint to path atomically (lpi_save)."""
        self._call("lpi_save", _c_path(path))

    def save_bytes(self):
        """The checkpoint as bytes (lpi_save_buffer)."""
        size = c_size_t()
        del self._pending[:]
        status = lib.lpi_save_buffer(self._h(), None, 0, byref(size))
        if status != 0:
            _raise(status, _text(lib.lpi_last_error(self._handle)))
        buf = ctypes.create_string_buffer(size.value)
        self._call("lpi_save_buffer", buf, size.value, byref(size))
        return buf.raw[:size.value]

    @classmethod
    def _adopt(cls, handle):
        """Wraps a handle made by lpi_load*, as the subclass of its kind."""
        # Generic and moment systems cannot be saved.
        classes = {"sine-euler": SineEuler, "rigid-body": RigidBody, "pendulum": Pendulum}
        kind = classes[_text(lib.lpi_kind(handle))]
        self = kind.__new__(kind)
        self._handle = handle
        self._keep, self._pending = [], []
        self._threads = 1
        self._seconds_per_step = None
        self._finalizer = weakref.finalize(self, _destroy, handle, self._keep)
        return self

    def __repr__(self):
        if self.closed:
            return "<%s (closed)>" % type(self).__name__
        return "<%s dim=%d method=%r t=%g>" % (type(self).__name__, self.dim, self.method, self.time)


class RigidBody(System):
    """Free rigid body on so(3)*: H = sum m_k^2 / (2 I_k), Casimir |m|^2.
    Splits "casimir-shift" (default) and "axes"."""

    def __init__(self, I1, I2, I3):
        super().__init__("lpi_rigid_body_create", _real(I1, "I1"), _real(I2, "I2"), _real(I3, "I3"))

    def exact(self, t):
        """The exact solution at time self.time + t from the current state (unchanged)."""
        ptr, result = _doubles_out(3)
        self._call("lpi_rigid_body_exact", _real(t, "t"), ptr)
        return result()


class Pendulum(System):
    """Planar pendulum on e(2)*: H = x3^2/2 + x2, Casimir x1^2 + x2^2."""

    def __init__(self):
        super().__init__("lpi_pendulum_create")


class Generic(System):
    """A user-defined Lie-Poisson system: {x_i, x_j} = sum c x_k over the
    brackets (i, j, k, c) (0-based). Pieces and Casimirs are Python callables.

        g = Generic(3, [(0, 1, 2, -1.0), (0, 2, 1, 1.0), (1, 2, 0, -1.0)])
        g.add_piece([0], lambda x: [x[0] / I1], lambda x: 0.5 * x[0] ** 2 / I1)
        g.add_casimir(lambda x: x[0] ** 2 + x[1] ** 2 + x[2] ** 2)

    A callback that raises makes the calling method raise CallbackError (with
    the callback's exception as __cause__) and leaves the state unchanged."""

    def __init__(self, dim, brackets=(), _create=None):
        if _create is not None:
            super().__init__(_create)
            return
        rows = [tuple(b) for b in brackets]
        if any(len(r) != 4 for r in rows):
            raise ValueError("each bracket is (i, j, k, c)")
        i, nnz = _int32s([r[0] for r in rows], "bracket index i")
        j, _ = _int32s([r[1] for r in rows], "bracket index j")
        k, _ = _int32s([r[2] for r in rows], "bracket index k")
        c = (c_double * max(nnz, 1))(*[_real(r[3], "bracket coefficient") for r in rows])
        super().__init__("lpi_generic_create", _integer(dim, "dim", "size"), nnz, i, j, k, c)

    def _guard(self, body):
        """Wraps a callback body: any exception is kept for the caller and
        reported to the library as failure (never crosses into C)."""
        pending = self._pending  # not self: the callbacks must not keep the system alive

        def run(*args):
            try:
                body(*args)
                return 0
            except BaseException as e:  # noqa: B902 - everything must stop here
                if not pending:
                    pending.append(e)
                return 1
        return run

    def add_piece(self, indices, gradient, energy):
        """Appends the piece H(x_sigma), sigma = indices (abelian). gradient(x_sigma)
        returns the n partial derivatives, energy(x_sigma) the value."""
        idx, n = _int32s(indices, "piece index")

        def grad_body(m, x, out, user):
            g = gradient(_callback_view(x, m))
            if len(g) != m:
                raise ValueError("gradient returned %d values for %d indices" % (len(g), m))
            for q in range(m):
                out[q] = float(g[q])

        def energy_body(m, x, out, user):
            out[0] = float(energy(_callback_view(x, m)))

        g_fn = _lib.GRADIENT_FN(self._guard(grad_body))
        e_fn = _lib.ENERGY_FN(self._guard(energy_body))
        self._call("lpi_add_piece", n, idx, g_fn, e_fn, None)
        self._keep.extend((g_fn, e_fn))

    def add_casimir(self, casimir):
        """Declares a Casimir: casimir(x) of the full state returns a float."""
        def body(dim, x, out, user):
            out[0] = float(casimir(_callback_view(x, dim)))

        fn = _lib.CASIMIR_FN(self._guard(body))
        self._call("lpi_add_casimir", fn, None)
        self._keep.append(fn)

    def poisson_rank(self, x=None):
        """Numerical rank of the Poisson matrix at x (default: the current state)."""
        if x is None:
            x = self.get_state()
        ptr, n, _keep = _doubles_in(x, "x")
        out = c_size_t()
        self._call("lpi_poisson_rank", ptr, n, byref(out))
        return out.value


class Moments(Generic):
    """The 8-dimensional algebra of second and fourth moments (McLachlan 1993),
    with Casimirs I and K built in. Add pieces with add_piece on the abelian sets
    {0,3}, {1,5}, {2,7}, {3,4,5,6,7} and add_product_piece for H(x1 x3)."""

    def __init__(self):
        super().__init__(8, _create="lpi_moments_create")

    def add_product_piece(self, h, dh):
        """Appends H(x1 x3) with its closed-form flow; h(u) and dh(u) = H'(u)."""
        def scalar_body(f):
            def body(u, out, user):
                out[0] = float(f(u))
            return body

        h_fn = _lib.SCALAR_FN(self._guard(scalar_body(h)))
        dh_fn = _lib.SCALAR_FN(self._guard(scalar_body(dh)))
        self._call("lpi_moments_add_product_piece", h_fn, dh_fn, None)
        self._keep.extend((h_fn, dh_fn))


class SineEuler(System):
    """Zeitlin's sine-Euler truncation of 2D Euler on the torus, N odd >= 3.
    modes: complex N x N (entry [a][b] is mode (a, b) mod N, FFT order);
    grid: real vorticity N x N at (2 pi a / N, 2 pi b / N). Needs FFTW in the
    library (UnsupportedError otherwise)."""

    def __init__(self, N):
        super().__init__("lpi_sine_euler_create", _integer(N, "N", "int32"))

    @property
    def N(self):
        out = c_int32()
        self._call("lpi_sine_euler_size", byref(out))
        return out.value

    def get_modes(self):
        N = self.N
        n = 2 * N * N
        if np is not None:
            out = np.empty((N, N), dtype=np.complex128)
            self._call("lpi_sine_euler_get_modes", out.ctypes.data_as(_lib.c_double_p), n)
            return out
        buf = (c_double * n)()
        self._call("lpi_sine_euler_get_modes", buf, n)
        return [[complex(buf[2 * (a * N + b)], buf[2 * (a * N + b) + 1]) for b in range(N)]
                for a in range(N)]

    def set_modes(self, modes):
        """Sets the modes (checked Hermitian, then symmetrised); time reset to 0."""
        if np is not None:
            a = modes
            if not (isinstance(a, np.ndarray) and a.dtype == np.complex128 and a.flags.c_contiguous):
                a = np.ascontiguousarray(_real_array(modes, "modes", "iufc"), dtype=np.complex128)
            self._call("lpi_sine_euler_set_modes", a.ctypes.data_as(_lib.c_double_p), 2 * a.size)
            return
        flat = []
        for row in modes:
            for z in row:
                if isinstance(z, (bool, str, bytes)) or not isinstance(z, numbers.Number):
                    raise TypeError("modes must be complex numbers, not %s" % type(z).__name__)
                z = complex(z)
                flat.extend((z.real, z.imag))
        buf = (c_double * max(len(flat), 1))(*flat)
        self._call("lpi_sine_euler_set_modes", buf, len(flat))

    modes = property(get_modes, set_modes)

    def get_grid(self):
        N = self.N
        if np is not None:
            out = np.empty((N, N), dtype=np.float64)
            self._call("lpi_sine_euler_get_grid", out.ctypes.data_as(_lib.c_double_p), N * N)
            return out
        buf = (c_double * (N * N))()
        self._call("lpi_sine_euler_get_grid", buf, N * N)
        return [list(buf[a * N:(a + 1) * N]) for a in range(N)]

    def set_grid(self, w):
        """Sets the vorticity from its N x N grid values; time reset to 0."""
        if np is not None:
            ptr, n, _keep = _doubles_in(_real_array(w, "grid").astype(np.float64).reshape(-1), "grid")
        else:
            ptr, n, _keep = _doubles_in([v for row in w for v in row], "grid")
        self._call("lpi_sine_euler_set_grid", ptr, n)

    grid = property(get_grid, set_grid)

    def enstrophy(self):
        out = c_double()
        self._call("lpi_sine_euler_enstrophy", byref(out))
        return out.value

    def casimir_traces(self, kmax):
        """[(1/N) tr W^k for k = 1 .. kmax]."""
        kmax = _integer(kmax, "kmax", "int32")
        ptr, result = _doubles_out(max(kmax, 0))
        if kmax < 1:  # let the library name the error
            ptr = (c_double * 1)()
        self._call("lpi_sine_euler_casimir_traces", kmax, ptr)
        return result()

    def fft_floor(self, nsteps):
        """(seconds per step, transforms per step) of FFTW alone for nsteps steps."""
        sec, count = c_double(), c_double()
        self._call("lpi_sine_euler_fft_floor", _integer(nsteps, "nsteps", "int64"), byref(sec), byref(count))
        return sec.value, count.value


# ---- checkpoints ----------------------------------------------------------------

def load(path):
    """A system restored from a checkpoint file (lpi_load); it continues the
    saved trajectory bit for bit, with the saved method and split."""
    handle = ctypes.c_void_p()
    _check_free(lib.lpi_load(byref(handle), _c_path(path)))
    return System._adopt(handle)


def load_bytes(data):
    """A system restored from checkpoint bytes (lpi_load_buffer)."""
    data = bytes(memoryview(data))  # bytes-like only: bytes(5) would be five zeros
    handle = ctypes.c_void_p()
    _check_free(lib.lpi_load_buffer(byref(handle), data, len(data)))
    return System._adopt(handle)


# ---- FFTW wisdom (process-wide) -----------------------------------------------

def fftw_wisdom_import_file(path):
    _check_free(lib.lpi_fftw_wisdom_import_file(_c_path(path)))


def fftw_wisdom_export_file(path):
    _check_free(lib.lpi_fftw_wisdom_export_file(_c_path(path)))


def fftw_wisdom_import_string(wisdom):
    _check_free(lib.lpi_fftw_wisdom_import_string(_c_string(wisdom, "wisdom")))


def fftw_wisdom_export_string():
    length = c_size_t()
    status = lib.lpi_fftw_wisdom_export_string(None, 0, byref(length))
    if status != STATUS["LPI_ERR_SIZE"]:
        _check_free(status)
    buf = ctypes.create_string_buffer(length.value + 1)
    _check_free(lib.lpi_fftw_wisdom_export_string(buf, len(buf), byref(length)))
    return buf.value.decode()
