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

Attributes
----------
version : str
    The loaded library's version, "MAJOR.MINOR.PATCH" (also ``__version__``).
version_number : int
    The same as one number to compare, MAJOR * 10000 + MINOR * 100 + PATCH.
HAVE_NUMPY : bool
    True when arrays are numpy arrays.
STATUS : dict
    The status codes by name, read from the library; each is also a module
    attribute (``LPI_OK``, ``LPI_ERR_SIZE``, ..., ``LPI_STOPPED``).
"""
from __future__ import annotations

import collections
import collections.abc
import contextlib
import ctypes
import math
import numbers
import operator
import os
import signal
import sys
import threading
import time
import weakref
from ctypes import byref, c_char_p, c_double, c_int32, c_size_t
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

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

# Type aliases: numpy is optional, so arrays are typed loosely.
#: An array argument: a sequence of real numbers, or a numpy array.
ArrayIn = Any
#: An array result: a numpy array with numpy, else a list.
ArrayOut = Any
#: A file name.
PathLike = Union[str, bytes, os.PathLike]
#: ``observer(system, step, t)`` of `System.step`; a truthy return stops the run.
Observer = Callable[["System", int, float], Any]

__all__ = [
    "version", "version_number", "methods", "Method", "status_name", "status_message", "HAVE_NUMPY",
    "System", "Trajectory", "RigidBody", "Pendulum", "Generic", "Moments", "SineEuler",
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
    TypeError for a non-integer (a float, a string, a bool, numpy's bool_ -
    named bool from numpy 2 on - which has an __index__ of its own),
    OverflowError outside the type's range."""
    if isinstance(value, bool) or type(value).__name__ in ("bool_", "bool"):
        raise TypeError("%s must be an integer, not %s" % (what, type(value).__name__))
    try:
        v = operator.index(value)
    except TypeError:
        raise TypeError("%s must be an integer, not %s" % (what, type(value).__name__)) from None
    lo, hi = _C_INTEGER_RANGES[ctype]
    if not lo <= v <= hi:
        raise OverflowError("%s = %d is out of range for the C type (%d .. %d)" % (what, v, lo, hi))
    return v


def _zero_dim_of(value, kinds):
    """Whether value is a 0-d array (numpy's np.asarray(0.5), what numpy
    arithmetic on arrays often returns) whose dtype kind is one of kinds:
    a number in an array's clothing. Not bool ("b") nor, for reals, complex."""
    dtype = getattr(value, "dtype", None)
    return getattr(value, "shape", None) == () and getattr(dtype, "kind", None) in kinds


def _real(value, what):
    """value as a float: TypeError for anything but a real number (no strings)."""
    if _zero_dim_of(value, ("i", "u", "f")):
        return float(value)
    if isinstance(value, (bool, str, bytes)) or not isinstance(value, numbers.Real):
        raise TypeError("%s must be a real number, not %s" % (what, type(value).__name__))
    try:
        return float(value)
    except (TypeError, ValueError):  # registered as a number, not one (numpy's timedelta64)
        raise TypeError("%s must be a real number, not %s" % (what, type(value).__name__)) from None


def _complex(value, what):
    """value as a complex: TypeError for anything but a number (no strings)."""
    if _zero_dim_of(value, ("i", "u", "f", "c")):
        return complex(value)
    if isinstance(value, (bool, str, bytes)) or not isinstance(value, numbers.Number):
        raise TypeError("%s must be a complex number, not %s" % (what, type(value).__name__))
    try:
        return complex(value)
    except (TypeError, ValueError):
        raise TypeError("%s must be a complex number, not %s" % (what, type(value).__name__)) from None


def _callable(value, what):
    """value itself if it can be called, else TypeError: the library hands C
    a wrapper that always exists, so C's own check for NULL never sees None."""
    if not callable(value):
        raise TypeError("%s must be callable, not %s" % (what, type(value).__name__))
    return value


def _is_array(value):
    """Whether value is an array to read entry by entry: a sequence (list,
    tuple, array.array, range) or an array object (numpy's, anything with
    __array__) of at least one dimension. Not str, bytes or bytearray, nor a
    set, dict or iterator: iterating those gives characters, byte values, keys
    or an arbitrary order, never the numbers meant."""
    if type(value) in (list, tuple):  # the usual answers first: callbacks' results come here
        return True
    if isinstance(value, (float, int, str, bytes, bytearray)) or getattr(value, "ndim", 1) == 0:
        return False
    return isinstance(value, collections.abc.Sequence) or hasattr(value, "__array__")


def _array(value, what):
    """value itself if _is_array(value), else TypeError."""
    if not _is_array(value):
        raise TypeError("%s must be a sequence or array of numbers, not %s" % (what, type(value).__name__))
    return value


def _nested(values, what, convert=_real):
    """values, an array (of arrays ...) of numbers, as nested lists of
    convert(entry, what): what list mode reads, and numpy mode where numpy
    could only make an array of objects (2**70, None, a Fraction)."""
    return [_nested(v, what, convert) if _is_array(v) else convert(v, what)
            for v in _array(values, what)]


def _shape(nested):
    """The shape of a result of _nested, as numpy would give it ("ragged"
    where the rows differ)."""
    if not isinstance(nested, list):
        return ()
    inner = {_shape(v) for v in nested}
    return (len(nested),) + (inner.pop() if len(inner) == 1 else ("ragged",) if inner else ())


def _reals(values, what):
    """values, a one-dimensional array of real numbers, as a list of floats.
    The same checks in both modes (list-mode arguments, callback results)."""
    if type(values) in (list, tuple) and all(isinstance(v, float) for v in values):
        return list(values)  # nothing to check: the usual gradient's result, on the hot path
    flat = _nested(values, what)
    if any(isinstance(v, list) for v in flat):
        raise ValueError("%s must be one-dimensional, not of shape %s" % (what, _shape(flat)))
    return flat


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


def status_name(status: int) -> str:
    """The name of a status code.

    Parameters
    ----------
    status : int
        A status returned by the library.

    Returns
    -------
    str
        ``"LPI_ERR_SIZE"`` for -3; ``"LPI_UNKNOWN_STATUS"`` for a value that is
        no status.
    """
    status = _integer(status, "status", "int")
    name = _text(lib.lpi_status_name(status))
    if name == "LPI_UNKNOWN_STATUS" and status in _KNOWN_AHEAD:
        return _KNOWN_AHEAD[status][0]
    return name


def status_message(status: int) -> str:
    """The one-line description of a status code.

    Parameters
    ----------
    status : int
        A status returned by the library.

    Returns
    -------
    str
        The library's description of `status`.
    """
    status = _integer(status, "status", "int")
    if status in _KNOWN_AHEAD and _text(lib.lpi_status_name(status)) == "LPI_UNKNOWN_STATUS":
        return _KNOWN_AHEAD[status][1]
    return _text(lib.lpi_status_message(status))


# ---- exceptions: one class per status, built from the library's own list ----

class LiePoissonError(Exception):
    """A liepoisson call failed.

    Each failing status raises its own subclass (`SizeError`, `FileError`,
    ...); a status this binding does not know raises this class itself.

    Parameters
    ----------
    status : int
        The status code (negative).
    message : str
        The library's detailed message.

    Attributes
    ----------
    status : int
        The status code.
    status_name : str
        Its name, such as ``"LPI_ERR_SIZE"``.
    message : str
        The library's detailed message (what was wrong, where).
    """
    status = None

    def __init__(self, status: int, message: str) -> None:
        self.status = status
        self.status_name = status_name(status)
        self.message = message
        super().__init__("%s: %s" % (self.status_name, message))

    def __reduce__(self):
        # Rebuilt from (status, message), so that pickle and copy work: an
        # error raised in a multiprocessing worker reaches the caller.
        return (type(self), (self.status, self.message))


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
    -13: ("LPI_ERR_BUSY", "the handle is busy (in one of its callbacks, or another thread's call)"),
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
# long enough to matter is therefore observed (lpi_set_observer) about every
# _OBSERVE_SECONDS; observing does not change the trajectory to the bit, so
# the cadence may follow the measured speed.
_OBSERVE_SECONDS = 0.05
# Before a step of this kind has been timed, its cost is guessed and the looks
# come this many times as often as the guess asks: the guess is off by up to
# 40x (the sine-Euler matrix methods cost N^3 a flow, not N^2), and a call
# cannot widen its cadence later without changing the bits of the trajectory
# (stopping and stepping on is not the same as one call for split sine-Euler).
# The time measured by the call then sets the cadence of the next ones.
_UNMEASURED_MARGIN = 64


class _SigintDeferred:
    """Holds SIGINT's Python handler back through a library call that may
    enter Python (a piece, a Casimir, an observer). Python runs a handler at
    the next bytecode of the main thread, which during such a call is the
    first one of a callback, before it can catch anything: ctypes then prints
    the exception and hands C an undefined result (a wrong energy, a step
    count C never meant). A SIGINT is recorded instead and the handler runs
    once the call has returned, or at an observer's look (run_pending).

    Only the main thread's outermost call installs the recorder; one nested
    in it (a call from a callback) shares the outer one's record, and one
    from another thread (which Python never interrupts) does nothing."""

    __slots__ = ("previous", "received", "owner")

    def __enter__(self):
        self.previous, self.received, self.owner = None, [], False
        if threading.current_thread() is threading.main_thread():
            handler = signal.getsignal(signal.SIGINT)
            outer = getattr(handler, "__self__", None)
            if isinstance(outer, _SigintDeferred):
                self.previous, self.received = outer.previous, outer.received
            elif callable(handler):
                self.previous, self.owner = handler, True
                signal.signal(signal.SIGINT, self._record)
        return self

    def _record(self, signum, frame):
        self.received.append(signum)

    def run_pending(self):
        """Runs the held-back handler for a SIGINT received (it may raise)."""
        if self.received:
            del self.received[:]
            self.previous(signal.SIGINT, None)

    def __exit__(self, *exc):
        if self.owner:
            signal.signal(signal.SIGINT, self.previous)
            self.run_pending()  # raising here, the call's own exception is the context
        return False


def _dividing_cadence(every, wanted):
    """The library observer's cadence when a caller's observer (every) and the
    SIGINT watch (about wanted steps) share it: a divisor of every, so that the
    caller's steps are all observed, near wanted, else every itself (then
    Ctrl-C is looked for at the caller's observations only)."""
    if every <= wanted:
        return every
    parts = -(-every // wanted)  # the fewest parts of at most wanted steps
    # cadences from wanted down to about wanted / 2, trying at most 64
    for n in range(parts, min(2 * parts, parts + 63) + 1):
        if every % n == 0:
            return every // n
    return every


# ---- methods ----------------------------------------------------------------

Method = collections.namedtuple("Method", "name order stages reference is_poisson")
Method.__doc__ = """A registered method, as `methods` lists it.

Attributes
----------
name : str
    What `System.set_method` takes.
order : int
    The order of accuracy.
stages : int
    Leapfrog stages per step (1 for the sequences and rk4).
reference : str
    The publication it comes from.
is_poisson : bool
    True for a Poisson integrator (keeps the Casimirs to round-off).
"""


def methods() -> List[Method]:
    """The registered methods, in the library's order.

    Returns
    -------
    list of Method
        Named tuples ``(name, order, stages, reference, is_poisson)``.
    """
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
    complex numbers, which numpy would otherwise convert or truncate, and
    for what list mode refuses (a set, a dict, bytes)."""
    convert = _complex if "c" in kinds else _real
    if isinstance(values, np.ndarray):
        a = values
        if a.dtype == object:  # each entry through the scalar check, as in list mode
            a = np.asarray(_nested(values, what, convert))
    else:
        # A sequence entry by entry, as list mode reads it: np.asarray would
        # take a bool among floats as 1.0.
        a = np.asarray(_nested(values, what, convert))
    if a.dtype.kind not in kinds:
        raise TypeError("%s must be %s numbers, not an array of %s"
                        % (what, "complex" if "c" in kinds else "real", a.dtype))
    return a


def _unmasked(values, what):
    """values itself, unless it is a numpy masked array with masked entries:
    ValueError then. Its data is an ndarray, which would otherwise reach C
    with whatever lies under the mask."""
    if isinstance(values, np.ma.MaskedArray) and np.ma.is_masked(values):
        raise ValueError("%s has masked entries (missing values); fill them or pass the data" % what)
    return values


def _c_ready(a):
    """Whether C can take the array's memory as it is: C-contiguous and aligned
    for its type (np.frombuffer at an odd offset, or a field of a packed
    record, is neither a copy nor aligned)."""
    return a.flags.c_contiguous and a.flags.aligned


def _doubles_in(values, what="values"):
    """(pointer, length, keep-alive) for a flat sequence of real numbers. A
    C-contiguous, aligned float64 numpy vector is passed as it is (no copy);
    any other real array (float32, integers, a strided view, doubles at an
    address C may not read them from) is copied."""
    if np is not None:
        a = _unmasked(values, what)
        if not (isinstance(a, np.ndarray) and a.ndim == 1 and a.dtype == np.float64 and _c_ready(a)):
            a = _real_array(values, what)
            if a.ndim != 1:
                raise ValueError("%s must be one-dimensional, not of shape %s" % (what, a.shape))
            a = np.require(a, np.float64, ["C_CONTIGUOUS", "ALIGNED"])
        return a.ctypes.data_as(_lib.c_double_p), a.size, a
    vals = _reals(values, what)
    buf = (c_double * len(vals))(*vals)
    return buf, len(vals), buf


def _doubles_out(n, out=None):
    """(pointer, result-maker) for n output doubles; out, a C-contiguous, aligned
    float64 numpy array of n elements, is filled in place."""
    if np is not None:
        if out is None:
            out = np.empty(n, dtype=np.float64)
        elif not (isinstance(out, np.ndarray) and out.dtype == np.float64
                  and _c_ready(out) and out.flags.writeable and out.size == n):
            raise ValueError("out must be a writeable, aligned, C-contiguous float64 array of %d elements" % n)
        return out.ctypes.data_as(_lib.c_double_p), (lambda: out)
    if out is not None:
        raise ValueError("out= needs numpy")
    buf = (c_double * n)()
    return buf, (lambda: list(buf))


def _int32s(values, what):
    vals = [_integer(v, what, "int32") for v in _array(values, what)]
    return (c_int32 * max(len(vals), 1))(*vals), len(vals)


def _callback_view(ptr, n):
    # A copy: the pointer is valid only during the callback.
    if np is not None:
        return np.ctypeslib.as_array(ptr, (n,)).copy() if n else np.empty(0)
    return ptr[:n]


# ---- systems ------------------------------------------------------------------

class Trajectory:
    """States recorded by `System.integrate` at the requested times.

    Parameters
    ----------
    t, y, energy, casimirs : array_like or None
        The attributes below.

    Attributes
    ----------
    t : numpy.ndarray or list of float
        The times reached, shape ``(m,)``.
    y : numpy.ndarray or list of list of float
        The states, one row per time: shape ``(m, dim)``.
    energy : numpy.ndarray or list of float or None
        The energy at each time, when asked for.
    casimirs : numpy.ndarray or list of list of float or None
        The Casimirs at each time (shape ``(m, casimir_count)``), when asked for.
    """

    __slots__ = ("t", "y", "energy", "casimirs")

    def __init__(self, t: ArrayOut, y: ArrayOut, energy: Optional[ArrayOut] = None,
                 casimirs: Optional[ArrayOut] = None) -> None:
        self.t, self.y, self.energy, self.casimirs = t, y, energy, casimirs

    def __len__(self) -> int:
        return len(self.t)

    def __repr__(self):
        return "<Trajectory of %d times%s%s>" % (len(self.t), ", energy" if self.energy is not None else "",
                                                 ", casimirs" if self.casimirs is not None else "")


def _destroy(handle, lock):
    # A system's finalizer: it holds the handle and the lock only. The ctypes
    # callbacks stay on the system (_keep), so that a cycle through them and
    # the user's callables (a bound method of the system's owner) is
    # collectable; the finalizer's weakref callback runs before gc clears any
    # object of the cycle, and the library calls callbacks only inside a call
    # made through the live system, so none is freed while the handle could
    # call it. The lock is held by another thread only at interpreter exit,
    # with a daemon thread still inside a call: the handle is left to the
    # process's end rather than freed under that call.
    if not lock.acquire(blocking=False):
        return _BUSY
    try:
        return lib.lpi_destroy(handle)
    finally:
        lock.release()


# The functions that make a handle (System's create).
_CREATE_FUNCTIONS = frozenset(("lpi_rigid_body_create", "lpi_pendulum_create", "lpi_generic_create",
                               "lpi_moments_create", "lpi_sine_euler_create"))
_BUSY = STATUS.get("LPI_ERR_BUSY", -13)
_STOPPED = STATUS.get("LPI_STOPPED", 1)
_NO_DEFERRAL = contextlib.nullcontext()
_NAN = float("nan")
_OTHER_THREAD = ("the system is in use by another thread (a system is used by one thread at a "
                 "time: share it under a lock of your own); nothing was changed")


class _Claim:
    """Holds a system for this thread through one call, or a sequence of calls
    that belong together (a step with its observer, a query then a fill).

    ctypes releases the GIL during a call, so two threads could otherwise be
    inside the library on one handle at once, which it does not allow: the
    second thread gets BusyError instead. The lock is re-entrant, so a call
    from the system's own callback (same thread) still reaches the library,
    which refuses it with its own message."""

    __slots__ = ("_lock",)

    def __init__(self, system):
        self._lock = system._lock

    def __enter__(self):
        if not self._lock.acquire(blocking=False):
            _raise(_BUSY, _OTHER_THREAD)

    def __exit__(self, *exc):
        self._lock.release()
        return False


class System:
    """A handle to one integrated system.

    Create one through a subclass (`RigidBody`, `Pendulum`, `Generic`,
    `Moments`, `SineEuler`) or `load`; ``close()``, a ``with`` block or garbage
    collection releases it. ``copy.copy``, ``copy.deepcopy`` and pickle give
    independent systems through a checkpoint. A system is used by one thread
    at a time: a call while another thread is inside one on it raises
    `BusyError` and changes nothing.

    Parameters
    ----------
    create : str
        The library's ``lpi_*_create`` function (for subclasses): one of
        those that make a handle, any other name raises `ValueError`.
    args : tuple
        Its arguments after the handle.
    """

    def __init__(self, create: str, *args: Any) -> None:
        # Only a create function takes the handle's address first: another
        # function would take that address for a handle (lpi_destroy freed it).
        if create not in _CREATE_FUNCTIONS:
            raise ValueError("System is made by a subclass or load(); create must be one of %s, not %r"
                             % (", ".join(sorted(_CREATE_FUNCTIONS)), create))
        handle = ctypes.c_void_p()
        _check_free(getattr(lib, create)(byref(handle), *args))
        self._own(handle)

    def _own(self, handle):
        """Takes charge of a new handle (from a create function or lpi_load*)."""
        self._handle = handle
        self._keep = []        # ctypes callbacks the library holds, until it is destroyed
        self._pending = []     # exception raised inside a callback during the current call
        self._threads = 1
        self._seconds_per_step = None  # (what the cost depends on, seconds): step(), for the SIGINT watch
        self._lock = threading.RLock()  # held by the thread inside a call (_Claim)
        self._finalizer = weakref.finalize(self, _destroy, handle, self._lock)  # not _keep: see _destroy

    # lifetime
    def close(self) -> None:
        """Release the handle now (idempotent).

        Raises
        ------
        BusyError
            When called from one of this system's own callbacks (a piece, a
            Casimir or an observer), or while another thread is inside a call
            on it: the system stays open and unchanged.
        """
        if not self._finalizer.alive:
            return
        with _Claim(self):
            if not self._finalizer.alive:
                return
            self._finalizer.detach()
            status = _destroy(self._handle, self._lock)
            if status != 0:  # BUSY: the handle and its callbacks stay as they were
                self._finalizer = weakref.finalize(self, _destroy, self._handle, self._lock)
                _raise(status, _text(lib.lpi_last_error(self._handle)))
            del self._keep[:]  # nothing can call them now

    @property
    def closed(self) -> bool:
        """Whether the handle has been released.

        Returns
        -------
        bool
            True after `close`.
        """
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
        status and returns the status otherwise (LPI_OK, LPI_STOPPED). On a
        system that holds Python callbacks, SIGINT's handler is held back
        until the call has returned (_SigintDeferred)."""
        with _Claim(self), (_SigintDeferred() if self._keep else _NO_DEFERRAL):
            del self._pending[:]
            status = getattr(lib, name)(self._h(), *args)
            if status < 0:
                cause = self._pending[0] if self._pending else None
                del self._pending[:]
                if cause is not None and not isinstance(cause, Exception):
                    raise cause  # KeyboardInterrupt, SystemExit: not ours to wrap
                _raise(status, _text(lib.lpi_last_error(self._handle)), cause)
            return status

    def _give_callbacks(self, callbacks, name, *args):
        """lpi_<name>(handle, *args), a call that hands C the ctypes callbacks
        to hold. They are kept first: an exception as the call returns (a
        KeyboardInterrupt) must not free what C now points to. C refusing
        them (a failed status) is the only case that drops them again."""
        self._keep.extend(callbacks)
        try:
            self._call(name, *args)
        except LiePoissonError:
            self._drop(callbacks)
            raise

    def _drop(self, callbacks):
        """Removes these ctypes callbacks (by identity) from those kept."""
        for fn in callbacks:
            for i, kept in enumerate(self._keep):
                if kept is fn:
                    del self._keep[i]
                    break

    def _query(self, function, *args):
        """function(handle, *args) for a function that returns no status (a
        name, the time, a size); the string a name points to belongs to the
        handle, so it is read under the claim too."""
        with _Claim(self):
            return function(self._h(), *args)

    @property
    def last_error(self) -> str:
        """The message of the most recent failed call on this system.

        Returns
        -------
        str
            The message, ``""`` if no call failed.
        """
        return self._query(lambda h: _text(lib.lpi_last_error(h)))

    @property
    def kind(self) -> str:
        """The system's kind.

        Returns
        -------
        str
            ``"rigid-body"``, ``"pendulum"``, ``"generic"``, ``"moments"`` or
            ``"sine-euler"``.
        """
        return self._query(lambda h: _text(lib.lpi_kind(h)))

    # method and split
    @property
    def method(self) -> str:
        """The method's name.

        Returns
        -------
        str
            ``"leapfrog"`` until set, ``"custom"`` after `set_composition`;
            an alias is reported by its name. A system from `load` reports
            the saved method.
        """
        return self._query(lambda h: _text(lib.lpi_get_method(h)))

    @method.setter
    def method(self, name: str) -> None:
        self.set_method(name)

    def set_method(self, name: str) -> None:
        """Choose the integration method.

        Parameters
        ----------
        name : str
            A name from `methods`, or ``"triple-jump-<p>"`` / ``"suzuki-<p>"``
            for even p from 2 to 16.

        Raises
        ------
        InvalidArgumentError
            An unknown name; the method is unchanged.
        """
        self._call("lpi_set_method", _c_string(name, "method"))

    @property
    def split(self) -> str:
        """The split's name.

        Returns
        -------
        str
            The name set, or the system's default split.
        """
        return self._query(lambda h: _text(lib.lpi_get_split(h)))

    @split.setter
    def split(self, name: str) -> None:
        self.set_split(name)

    def set_split(self, name: str) -> None:
        """Choose how the Hamiltonian is split into pieces.

        Parameters
        ----------
        name : str
            A split of this system (the rigid body: ``"casimir-shift"``,
            ``"axes"``).

        Raises
        ------
        InvalidArgumentError
            A split this system does not have; the split is unchanged.
        """
        self._call("lpi_set_split", _c_string(name, "split"))

    def set_composition(self, gammas: ArrayIn) -> None:
        """Use a symmetric composition of leapfrog (method ``"custom"``).

        Parameters
        ----------
        gammas : sequence of float
            The weights of the leapfrog stages, symmetric, summing to 1.
        """
        ptr, n, _keep = _doubles_in(gammas, "gammas")
        self._call("lpi_set_composition", n, ptr)

    def flows_per_step(self) -> int:
        """The number of piece flows one step computes.

        Returns
        -------
        int
            Flows per step with the current method and split.
        """
        out = c_size_t()
        self._call("lpi_flows_per_step", byref(out))
        return out.value

    def set_implicit_options(self, tolerance: float = 1e-13, max_iterations: int = 100) -> None:
        """Set the fixed-point iteration of the implicit baselines.

        Parameters
        ----------
        tolerance : float, optional
            The iteration stops when a correction is below this (default 1e-13).
        max_iterations : int, optional
            Iterations before `NoConvergenceError` (default 100).
        """
        self._call("lpi_set_implicit_options", _real(tolerance, "tolerance"),
                   _integer(max_iterations, "max_iterations", "int32"))

    @property
    def threads(self) -> int:
        """The number of threads a step may use (sine-Euler).

        Returns
        -------
        int
            The count set (default 1).
        """
        return self._threads

    @threads.setter
    def threads(self, n: int) -> None:
        n = _integer(n, "threads", "int32")
        self._call("lpi_set_threads", n)
        self._threads = n

    # state
    @property
    def dim(self) -> int:
        """The dimension of the state vector.

        Returns
        -------
        int
            The number of state entries.
        """
        return self._query(lib.lpi_dim)

    def __len__(self):
        return self.dim

    def get_state(self, out: Optional[ArrayOut] = None) -> ArrayOut:
        """The current state.

        Parameters
        ----------
        out : numpy.ndarray, optional
            A writeable, aligned, C-contiguous float64 array of `dim` entries to fill.

        Returns
        -------
        numpy.ndarray or list of float
            The state (`out` when given).
        """
        n = self.dim
        ptr, result = _doubles_out(n, out)
        self._call("lpi_get_state", ptr, n)
        return result()

    def set_state(self, x: ArrayIn) -> None:
        """Set the state and reset the time to 0.

        Parameters
        ----------
        x : sequence of float
            `dim` real numbers.

        Raises
        ------
        SizeError
            Not `dim` numbers; the state is unchanged.
        TypeError
            Not real numbers (strings, complex numbers, booleans).
        """
        ptr, n, _keep = _doubles_in(x, "state")
        self._call("lpi_set_state", ptr, n)

    state = property(get_state, set_state)

    @property
    def time(self) -> float:
        """The current time.

        Returns
        -------
        float
            The time reached; `set_state` resets it to 0.
        """
        return self._query(lib.lpi_time)

    def step(self, dt: float, nsteps: int = 1, *, observer: Optional[Observer] = None,
             every: int = 1) -> int:
        """Advance the system by `nsteps` steps of size `dt`.

        Parameters
        ----------
        dt : float
            The step size: finite and nonzero; negative integrates backwards.
        nsteps : int, optional
            The number of steps, >= 0 (default 1).
        observer : callable, optional
            ``observer(system, step, t)``, called after every `every`-th step
            with this system, the number of steps done so far in this call and
            the time reached. The system then holds exactly the state a call of
            `step` steps would leave, and observing changes no bit of the
            trajectory. The observer may read the system (state, energy,
            Casimirs, ``save``); changing it raises `BusyError`. A truthy return
            stops the run after that step; an exception stops it there too and
            then propagates from ``step``.
        every : int, optional
            Steps between two calls of `observer`, >= 1 (default 1).

        Returns
        -------
        int
            The number of steps done: `nsteps`, or fewer when the observer (or
            Ctrl-C) stopped the run; ``time`` has then advanced by that many
            steps.

        Raises
        ------
        NonFiniteError, CallbackError
            A step failed; the state and time are those before the call.
        UnsupportedError
            The method is isomp or rk4-matrix and the BLAS/LAPACK library
            cannot be loaded at its first step, or the system runs threads
            and this is a fork child (lpi_step(3)).

        Notes
        -----
        Ctrl-C (SIGINT) during a long call from the main thread: the run
        stops within about a twentieth of a second and the SIGINT handler
        runs there (``KeyboardInterrupt`` by default), the system holding
        exactly the state of a call of the steps done. From another thread
        the handler runs when the whole call returns (Python runs signal
        handlers in the main thread only). With an
        observer, Ctrl-C is looked for at a cadence that divides `every` (at
        the observer's own calls when no such cadence is near the wanted one).
        """
        dt = _real(dt, "dt")
        nsteps = _integer(nsteps, "nsteps", "int64")
        every = _integer(every, "every", "int64")
        if every < 1:
            raise ValueError("every must be >= 1, not %d" % every)
        if observer is not None:
            if not callable(observer):
                raise TypeError("observer must be callable, not %s" % type(observer).__name__)
        # One claim for the observer set, the step, its removal and the
        # timing kept: once steps are done, nothing may raise BusyError.
        with _Claim(self):
            key = self._step_cost_key()
            sigint_every = self._observation_interval(nsteps, key)
            started = time.perf_counter()
            if observer is None and not sigint_every:
                self._call("lpi_step", dt, nsteps)
                done = nsteps
            else:
                done = self._step_observed(dt, nsteps, observer, every, sigint_every, key, started)
            if done > 0:
                self._seconds_per_step = (key, (time.perf_counter() - started) / done)
        return done

    def integrate(self, t_eval: ArrayIn, dt: float, *, energy: bool = False,
                  casimirs: bool = False) -> Trajectory:
        """Integrate with fixed steps through the times `t_eval`, keeping the states there.

        Like ``scipy.integrate.solve_ivp(..., t_eval=...)`` with a fixed step:
        the system starts from its current state and time and ends at the last
        requested time.

        Parameters
        ----------
        t_eval : sequence of float
            The times at which to record the state, in the direction of `dt`
            (non-decreasing for dt > 0, non-increasing for dt < 0), none before
            the current time. Each must be a whole number of steps from the
            current time (to a millionth of a step, or the rounding of a long
            run): the step is not stretched to meet a time.
        dt : float
            The step size, finite and nonzero.
        energy : bool, optional
            Also record the energy at each time (default False).
        casimirs : bool, optional
            Also record the Casimirs at each time (default False).

        Returns
        -------
        Trajectory
            ``.t`` the times reached (``t_eval`` up to the rounding of the
            library's time), ``.y`` the states, one row per time (shape
            ``(len(t), dim)``; note: scipy's ``.y`` is the transpose),
            ``.energy`` and ``.casimirs`` when asked for (else None).

        Raises
        ------
        ValueError
            A time is not a whole number of steps from the current time, or
            lies behind the previous one; nothing has been stepped then.
        NonFiniteError, CallbackError
            A step failed: the system holds the state of the last requested
            time reached.

        Examples
        --------
        >>> body = RigidBody(1.0, 2.0, 3.0)
        >>> body.state = [1.0, 0.5, -0.3]
        >>> sol = body.integrate([0.0, 0.5, 1.0], 0.01, casimirs=True)
        >>> len(sol.t), len(sol.y[0])
        (3, 3)
        """
        dt = _real(dt, "dt")
        if not math.isfinite(dt) or dt == 0.0:
            raise ValueError("dt must be finite and nonzero, not %r" % dt)
        times = _reals(t_eval, "t_eval")
        with _Claim(self):  # the time the steps are counted from is the one stepped from
            return self._integrate(times, dt, energy, casimirs)

    def _integrate(self, times, dt, energy, casimirs):
        start = self.time
        counts, previous = [], 0
        for t in times:
            # Said first: NaN passes every comparison below.
            if not math.isfinite(t):
                raise ValueError("t_eval entry %r is not finite" % t)
            # An infinite count (a time too far for dt) is ahead or behind by its sign.
            exact = (t - start) / dt
            n = round(exact) if math.isfinite(exact) else exact
            if abs(exact - n) > max(1e-6, 8 * sys.float_info.epsilon * abs(exact)):
                raise ValueError("t_eval entry %r is %.6g steps of %r from the time %r: not a whole number"
                                 % (t, exact, dt, start))
            if n < previous:
                raise ValueError("t_eval entry %r lies behind %s (steps of %r from the time %r)"
                                 % (t, "the previous one" if counts else "the current time", dt, start))
            if n > 2**63 - 1:  # refused here, not after stepping to the times before it
                raise ValueError("t_eval entry %r is %.6g steps of %r from the time %r: more than a "
                                 "step count holds (2**63 - 1)" % (t, exact, dt, start))
            counts.append(n)
            previous = n
        dim, ncas = self.dim, self.casimir_count
        out_t = [0.0] * len(times)
        out_e = [0.0] * len(times) if energy else None
        if np is not None:
            out_y = np.empty((len(times), dim))
            out_c = np.empty((len(times), ncas)) if casimirs else None
        else:
            out_y, out_c = [None] * len(times), ([None] * len(times) if casimirs else None)
        done = 0
        for i, n in enumerate(counts):
            if n > done:
                done += self.step(dt, n - done)
            out_t[i] = self.time
            out_y[i] = self.get_state(out_y[i] if np is not None else None)
            if energy:
                out_e[i] = self.energy()
            if casimirs:
                out_c[i] = self.casimirs(out_c[i] if np is not None else None)
        if np is not None:
            out_t = np.array(out_t)
            out_e = np.array(out_e) if energy else None
        return Trajectory(out_t, out_y, out_e, out_c)

    def _observation_interval(self, nsteps, key):
        """Steps between looks for a SIGINT during step(), or 0 for none: the
        call is short, this is not the main thread (only it runs signal
        handlers) or SIGINT has no Python handler. key: _step_cost_key()."""
        if nsteps < 2 or threading.current_thread() is not threading.main_thread():
            return 0
        if not callable(signal.getsignal(signal.SIGINT)):
            return 0
        measured = self._seconds_per_step
        if measured is not None and measured[0] == key:
            seconds = measured[1]
        else:
            # Not timed with this method yet: a guess of 1e-7 s per flow and
            # state entry, or 2e-5 s per flow where the flows call Python,
            # looked at _UNMEASURED_MARGIN times as often (each look costs a
            # few microseconds, far less than the steps between them).
            flows = max(key[-1], 1)
            seconds = flows * (2e-5 if self._keep else 1e-7 * max(self.dim, 1)) * _UNMEASURED_MARGIN
        if seconds * nsteps < _OBSERVE_SECONDS:
            return 0
        return max(1, min(nsteps, int(_OBSERVE_SECONDS / max(seconds, 1e-12))))

    def _step_cost_key(self):
        """What a step's cost depends on besides the state: the method, the
        split, the thread count and the flows per step (pieces added)."""
        flows = c_size_t(0)
        if self._query(lib.lpi_flows_per_step, byref(flows)) != 0:
            flows.value = 0
        return (self.method, self.split, self._threads, flows.value)

    def _step_observed(self, dt, nsteps, observer, every, sigint_every, key, started):
        """lpi_step under one library observer that serves both the caller's
        observer (at the multiples of every) and the SIGINT watch (about every
        sigint_every steps; 0: none). Returns the steps done. Called under the
        claim; key and started time the first call of a method (step())."""
        if observer is None:
            cadence = sigint_every
        elif sigint_every:
            cadence = _dividing_cadence(every, sigint_every)
        else:
            cadence = every
        # SIGINT only sets a flag during the call whatever its length (the
        # observer is Python); the observer runs the handler that was in
        # place, and stops the step if that raised.
        deferred = _SigintDeferred()
        raised, stopped_at = [], []

        def observe(handle, step, t, user):
            try:
                # Timed at each look, so that a run Ctrl-C ends still sets the
                # cadence of the next (step() times a whole run again).
                self._seconds_per_step = (key, (time.perf_counter() - started) / step)
                deferred.run_pending()
                if observer is not None and step % every == 0 and observer(self, step, t):
                    stopped_at.append(step)
                    return 1
            except BaseException as e:  # noqa: B902 - must not cross into C
                raised.append(e)
                stopped_at.append(step)
                return 1
            return 0

        c_observer = _lib.OBSERVER_FN(observe)
        self._keep.append(c_observer)  # before C holds it, until C has let it go
        with deferred:
            start_time = lib.lpi_time(self._handle)
            refused = False  # C refused the observer (from a callback of this system: BUSY)
            try:
                try:
                    self._call("lpi_set_observer", cadence, c_observer, None)
                except LiePoissonError:
                    refused = True
                    raise
                status = self._call("lpi_step", dt, nsteps)
            finally:
                if refused or lib.lpi_set_observer(self._handle, 0, _lib.OBSERVER_FN(), None) == 0:  # NULL: removed
                    self._drop((c_observer,))
            if raised:
                raise raised[0]
        if stopped_at:
            return stopped_at[0]
        if status == _STOPPED:
            # C stopped though no observer asked (an observer's result it
            # could not trust): the steps done are those the time shows.
            return int(round((lib.lpi_time(self._handle) - start_time) / dt))
        return nsteps

    def energy(self) -> float:
        """The energy of the current state.

        Returns
        -------
        float
            The Hamiltonian's value.
        """
        out = c_double()
        self._call("lpi_energy", byref(out))
        return out.value

    @property
    def casimir_count(self) -> int:
        """The number of Casimirs `casimirs` reports.

        Returns
        -------
        int
            The count.
        """
        return self._query(lib.lpi_casimir_count)

    def casimirs(self, out: Optional[ArrayOut] = None) -> ArrayOut:
        """The Casimirs of the current state.

        Parameters
        ----------
        out : numpy.ndarray, optional
            A writeable, aligned, C-contiguous float64 array of `casimir_count` entries.

        Returns
        -------
        numpy.ndarray or list of float
            The Casimirs (`out` when given).
        """
        n = self.casimir_count
        ptr, result = _doubles_out(n, out)
        self._call("lpi_casimirs", ptr, n)
        return result()

    # checkpoints
    def save(self, path: PathLike) -> None:
        """Write a checkpoint to a file, atomically (lpi_save).

        Parameters
        ----------
        path : str, bytes or os.PathLike
            The file to write.

        Raises
        ------
        FileError
            The file cannot be written (an `OSError`).
        UnsupportedError
            A system with Python callbacks (`Generic`, `Moments`).
        """
        self._call("lpi_save", _c_path(path))

    def save_bytes(self) -> bytes:
        """The checkpoint as bytes (lpi_save_buffer).

        Returns
        -------
        bytes
            What `load_bytes` restores.
        """
        size = c_size_t()
        with _Claim(self):  # the size queried is the size filled
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
        self._own(handle)
        return self

    # copies and pickles go through a checkpoint
    def __reduce__(self) -> Tuple[Any, ...]:
        """Pickle support: the system as its checkpoint bytes (lpi_save_buffer).

        Returns
        -------
        tuple
            ``(_from_checkpoint, (bytes, threads, planning))``; unpickling
            restores an independent system that continues the trajectory bit
            for bit (observers are not kept). The settings a checkpoint does
            not hold go with it: the thread count, and a sine-Euler system's
            FFTW planning, planned again at that rigor (with ``"measure"`` or
            ``"patient"``, the same plans only where the same FFTW wisdom is
            known: in this process, or after `fftw_wisdom_import_string`).
        """
        with _Claim(self):  # the settings of the state saved
            return (_from_checkpoint, (self.save_bytes(), self._threads, self._planning()))

    def _planning(self):
        """The FFTW planning rigor a copy must plan at; None where there is none."""
        return None

    def __copy__(self) -> "System":
        """An independent system in the same state (through a checkpoint).

        Returns
        -------
        System
            A new handle of the same kind; stepping one leaves the other as it is.
        """
        restore, args = self.__reduce__()
        return restore(*args)

    def __deepcopy__(self, memo: Dict[int, Any]) -> "System":
        """The same as ``copy.copy``: a system shares nothing with its copy.

        Parameters
        ----------
        memo : dict
            The ``copy.deepcopy`` memo (unused).

        Returns
        -------
        System
            A new, independent handle.
        """
        return self.__copy__()

    def __repr__(self):
        if self.closed:
            return "<%s (closed)>" % type(self).__name__
        try:
            return "<%s dim=%d method=%r t=%g>" % (type(self).__name__, self.dim, self.method, self.time)
        except BusyError:  # noqa: F821 - made by _scan_statuses
            return "<%s (in use by another thread)>" % type(self).__name__


class RigidBody(System):
    """The free rigid body on so(3)*: H = sum m_k^2 / (2 I_k), Casimir |m|^2.

    Splits ``"casimir-shift"`` (default) and ``"axes"``.

    Parameters
    ----------
    I1, I2, I3 : float
        The principal moments of inertia, positive.
    """

    def __init__(self, I1: float, I2: float, I3: float) -> None:
        super().__init__("lpi_rigid_body_create", _real(I1, "I1"), _real(I2, "I2"), _real(I3, "I3"))

    def exact(self, t: float) -> ArrayOut:
        """The exact solution (Jacobi elliptic functions) from the current state.

        Parameters
        ----------
        t : float
            The time to advance, from `time`.

        Returns
        -------
        numpy.ndarray or list of float
            The state at ``time + t``; the system is unchanged.
        """
        ptr, result = _doubles_out(3)
        self._call("lpi_rigid_body_exact", _real(t, "t"), ptr)
        return result()


class Pendulum(System):
    """The planar pendulum on e(2)*: H = x3^2/2 + x2, Casimir x1^2 + x2^2."""

    def __init__(self) -> None:
        super().__init__("lpi_pendulum_create")


class Generic(System):
    """A user-defined Lie-Poisson system with Python callables as pieces.

    The bracket is {x_i, x_j} = sum c x_k over the rows (i, j, k, c), 0-based.
    A callback that raises makes the calling method raise `CallbackError`
    (with the callback's exception as ``__cause__``) and leaves the state
    unchanged. Cannot be copied, pickled or saved.

    Parameters
    ----------
    dim : int
        The dimension of the state.
    brackets : sequence of (int, int, int, float)
        The structure constants (i, j, k, c).

    Examples
    --------
    >>> g = Generic(3, [(0, 1, 2, -1.0), (0, 2, 1, 1.0), (1, 2, 0, -1.0)])
    >>> g.add_piece([0], lambda x: [x[0] / 2.0], lambda x: 0.25 * x[0] ** 2)
    >>> g.add_casimir(lambda x: x[0] ** 2 + x[1] ** 2 + x[2] ** 2)
    """

    def __init__(self, dim: int, brackets: Sequence[Tuple[int, int, int, float]] = (),
                 _create: Optional[str] = None) -> None:
        if _create is not None:
            super().__init__(_create)
            return
        rows = [tuple(_array(b, "bracket")) for b in _array(brackets, "brackets")]
        if any(len(r) != 4 for r in rows):
            raise ValueError("each bracket is (i, j, k, c)")
        i, nnz = _int32s([r[0] for r in rows], "bracket index i")
        j, _ = _int32s([r[1] for r in rows], "bracket index j")
        k, _ = _int32s([r[2] for r in rows], "bracket index k")
        c = (c_double * max(nnz, 1))(*[_real(r[3], "bracket coefficient") for r in rows])
        super().__init__("lpi_generic_create", _integer(dim, "dim", "size"), nnz, i, j, k, c)

    def _guard(self, body, out_index):
        """Wraps a callback body: any exception is kept for the caller and
        reported to the library as failure (never crosses into C). The result
        (args[out_index]) is NaN until the body writes it, so that a body left
        early without a status C can trust fails there as non-finite rather
        than leaving C's default."""
        pending = self._pending  # not self: the callbacks must not keep the system alive

        def run(*args):
            try:
                args[out_index][0] = _NAN
                body(*args)
                return 0
            except BaseException as e:  # noqa: B902 - everything must stop here
                if not pending:
                    pending.append(e)
                return 1
        return run

    def add_piece(self, indices: Sequence[int], gradient: Callable[[Any], Sequence[float]],
                  energy: Callable[[Any], float]) -> None:
        """Append the piece H(x_sigma) of the Hamiltonian.

        Parameters
        ----------
        indices : sequence of int
            sigma, an abelian set of state indices.
        gradient : callable
            ``gradient(x_sigma)`` returns the len(sigma) partial derivatives.
        energy : callable
            ``energy(x_sigma)`` returns the piece's value.

        Raises
        ------
        NotAbelianError
            The indices do not commute under the bracket.
        TypeError
            `gradient` or `energy` is not callable.
        """
        _callable(gradient, "gradient")
        _callable(energy, "energy")
        idx, n = _int32s(indices, "piece index")

        def grad_body(m, x, out, user):
            g = _reals(gradient(_callback_view(x, m)), "gradient's result")
            if len(g) != m:
                raise ValueError("gradient returned %d values for %d indices" % (len(g), m))
            for q in range(m):
                out[q] = g[q]

        def energy_body(m, x, out, user):
            out[0] = _real(energy(_callback_view(x, m)), "energy's result")

        g_fn = _lib.GRADIENT_FN(self._guard(grad_body, 2))
        e_fn = _lib.ENERGY_FN(self._guard(energy_body, 2))
        self._give_callbacks((g_fn, e_fn), "lpi_add_piece", n, idx, g_fn, e_fn, None)

    def add_casimir(self, casimir: Callable[[Any], float]) -> None:
        """Declare a Casimir, which `casimirs` then reports.

        Parameters
        ----------
        casimir : callable
            ``casimir(x)`` of the full state returns a float.

        Raises
        ------
        TypeError
            `casimir` is not callable.
        """
        _callable(casimir, "casimir")

        def body(dim, x, out, user):
            out[0] = _real(casimir(_callback_view(x, dim)), "Casimir's result")

        fn = _lib.CASIMIR_FN(self._guard(body, 2))
        self._give_callbacks((fn,), "lpi_add_casimir", fn, None)

    def __reduce__(self) -> Tuple[Any, ...]:
        """Refuses: a checkpoint cannot hold Python callables.

        Raises
        ------
        TypeError
            Always, for pickle, ``copy.copy`` and ``copy.deepcopy`` alike.
        """
        raise TypeError("a %s system cannot be copied or pickled: its pieces and Casimirs are Python "
                        "callables, which a checkpoint does not hold; build a new one and set its state"
                        % type(self).__name__)

    def poisson_rank(self, x: Optional[ArrayIn] = None) -> int:
        """The numerical rank of the Poisson matrix.

        Parameters
        ----------
        x : sequence of float, optional
            The point (default: the current state).

        Returns
        -------
        int
            The rank.
        """
        if x is None:
            x = self.get_state()
        ptr, n, _keep = _doubles_in(x, "x")
        out = c_size_t()
        self._call("lpi_poisson_rank", ptr, n, byref(out))
        return out.value


class Moments(Generic):
    """The 8-dimensional algebra of second and fourth moments (McLachlan 1993).

    Casimirs I and K are built in. Add pieces with `add_piece` on the abelian
    sets {0,3}, {1,5}, {2,7}, {3,4,5,6,7} and `add_product_piece` for H(x1 x3).
    """

    def __init__(self) -> None:
        super().__init__(8, _create="lpi_moments_create")

    def add_product_piece(self, h: Callable[[float], float], dh: Callable[[float], float]) -> None:
        """Append H(x1 x3), integrated by its closed-form flow.

        Parameters
        ----------
        h : callable
            ``h(u)``, the piece as a function of u = x1 x3.
        dh : callable
            ``dh(u)``, its derivative H'(u).

        Raises
        ------
        TypeError
            `h` or `dh` is not callable.
        """
        _callable(h, "h")
        _callable(dh, "dh")

        def scalar_body(f, what):
            def body(u, out, user):
                out[0] = _real(f(u), what)
            return body

        h_fn = _lib.SCALAR_FN(self._guard(scalar_body(h, "h's result"), 1))
        dh_fn = _lib.SCALAR_FN(self._guard(scalar_body(dh, "dh's result"), 1))
        self._give_callbacks((h_fn, dh_fn), "lpi_moments_add_product_piece", h_fn, dh_fn, None)


class SineEuler(System):
    """Zeitlin's sine-Euler truncation of 2D Euler on the torus.

    ``modes``: complex N x N (entry [a][b] is mode (a, b) mod N, FFT order);
    ``grid``: real vorticity N x N at (2 pi a / N, 2 pi b / N).

    Parameters
    ----------
    N : int
        The truncation, odd, >= 3.

    Raises
    ------
    UnsupportedError
        The library was built without FFTW.
    """

    def __init__(self, N: int) -> None:
        super().__init__("lpi_sine_euler_create", _integer(N, "N", "int32"))

    @property
    def N(self) -> int:
        """The truncation N.

        Returns
        -------
        int
            N, odd.
        """
        out = c_int32()
        self._call("lpi_sine_euler_size", byref(out))
        return out.value

    def get_modes(self) -> Any:
        """The Fourier modes of the vorticity.

        Returns
        -------
        numpy.ndarray or list of list of complex
            N x N, Hermitian.
        """
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

    def _check_square(self, shape: Tuple[Any, ...], what: str) -> None:
        """SizeError unless shape is (N, N): the library checks only the count,
        which a (1, N*N) array or ragged rows would pass."""
        N = self.N
        if tuple(shape) != (N, N):
            _raise(STATUS["LPI_ERR_SIZE"], "%s must be %d x %d, not of shape %s" % (what, N, N, tuple(shape)))

    def _square_in(self, values: Any, what: str, complex_: bool = False) -> Tuple[Any, int, Any]:
        """(pointer, number of doubles, keep-alive) for an N x N array of real
        numbers, or of complex numbers as (re, im) pairs with complex_. A
        C-contiguous, aligned float64 (complex128) numpy array is passed as it
        is."""
        if np is not None:
            dtype = np.complex128 if complex_ else np.float64
            a = _unmasked(values, what)
            if not (isinstance(a, np.ndarray) and a.ndim == 2 and a.dtype == dtype and _c_ready(a)):
                if not isinstance(a, np.ndarray):  # ragged rows: SizeError, as in list mode (numpy's ValueError)
                    self._check_square(_shape(_nested(a, what, _complex if complex_ else _real)), what)
                a = np.require(_real_array(values, what, "iufc" if complex_ else "iuf"), dtype,
                               ["C_CONTIGUOUS", "ALIGNED"])
            self._check_square(a.shape, what)
            return a.ctypes.data_as(_lib.c_double_p), a.size * (2 if complex_ else 1), a
        rows = _nested(values, what, _complex if complex_ else _real)
        self._check_square(_shape(rows), what)
        flat = [v for row in rows for v in row]
        if complex_:
            flat = [part for z in flat for part in (z.real, z.imag)]
        buf = (c_double * max(len(flat), 1))(*flat)
        return buf, len(flat), buf

    def set_modes(self, modes: Any) -> None:
        """Set the modes (checked Hermitian, then symmetrised); the time becomes 0.

        Parameters
        ----------
        modes : array_like of complex
            N x N.

        Raises
        ------
        SizeError
            Not N x N.
        InvalidArgumentError
            Not Hermitian; the state is unchanged.
        """
        ptr, n, _keep = self._square_in(modes, "modes", complex_=True)
        self._call("lpi_sine_euler_set_modes", ptr, n)

    modes = property(get_modes, set_modes)

    def get_grid(self) -> Any:
        """The vorticity on the grid.

        Returns
        -------
        numpy.ndarray or list of list of float
            N x N real values.
        """
        N = self.N
        if np is not None:
            out = np.empty((N, N), dtype=np.float64)
            self._call("lpi_sine_euler_get_grid", out.ctypes.data_as(_lib.c_double_p), N * N)
            return out
        buf = (c_double * (N * N))()
        self._call("lpi_sine_euler_get_grid", buf, N * N)
        return [list(buf[a * N:(a + 1) * N]) for a in range(N)]

    def set_grid(self, w: Any) -> None:
        """Set the vorticity from its grid values; the time becomes 0.

        Parameters
        ----------
        w : array_like of float
            N x N real values. A complex array is refused (`TypeError`), not
            cast.

        Raises
        ------
        SizeError
            Not N x N.
        """
        ptr, n, _keep = self._square_in(w, "grid")
        self._call("lpi_sine_euler_set_grid", ptr, n)

    grid = property(get_grid, set_grid)

    def enstrophy(self) -> float:
        """The enstrophy of the current state.

        Returns
        -------
        float
            The enstrophy (a Casimir).
        """
        out = c_double()
        self._call("lpi_sine_euler_enstrophy", byref(out))
        return out.value

    def casimir_traces(self, kmax: int) -> ArrayOut:
        """The Casimirs (1/N) tr W^k of the vorticity matrix.

        Parameters
        ----------
        kmax : int
            The highest power, >= 1.

        Returns
        -------
        numpy.ndarray or list of float
            The traces for k = 1 .. kmax.
        """
        kmax = _integer(kmax, "kmax", "int32")
        ptr, result = _doubles_out(max(kmax, 0))
        if kmax < 1:  # let the library name the error
            ptr = (c_double * 1)()
        self._call("lpi_sine_euler_casimir_traces", kmax, ptr)
        return result()

    def fft_floor(self, nsteps: int) -> Tuple[float, float]:
        """The cost of FFTW alone over nsteps steps, for comparison with `step`.

        Parameters
        ----------
        nsteps : int
            Steps to time.

        Returns
        -------
        tuple of float
            (seconds per step, transforms per step).
        """
        sec, count = c_double(), c_double()
        self._call("lpi_sine_euler_fft_floor", _integer(nsteps, "nsteps", "int64"), byref(sec), byref(count))
        return sec.value, count.value

    @property
    def planning(self) -> str:
        """How FFTW chooses the line transforms' plans.

        Returns
        -------
        str
            ``"estimate"`` (the default), ``"measure"`` or ``"patient"``.
        """
        rigor = c_char_p()
        self._call("lpi_sine_euler_get_planning", byref(rigor))
        return _text(rigor.value)

    @planning.setter
    def planning(self, rigor: str) -> None:
        self.set_planning(rigor)

    def _planning(self):
        return self.planning

    def set_planning(self, rigor: str) -> None:
        """Plan the line transforms anew, now, at this FFTW rigor.

        ``"estimate"`` (the default) is deterministic: the same bits in every
        process on this machine and FFTW build. ``"measure"`` and
        ``"patient"`` time candidate plans: often faster, but another process
        may choose other plans and round differently, unless the same FFTW
        wisdom was imported first (`fftw_wisdom_import_file`). See
        lpi_sine_euler_set_planning(3).

        Parameters
        ----------
        rigor : str
            ``"estimate"``, ``"measure"`` or ``"patient"``.

        Raises
        ------
        InvalidArgumentError
            An unknown rigor; the plans are unchanged.
        """
        self._call("lpi_sine_euler_set_planning", _c_string(rigor, "rigor"))

    # ---- the sine-bracket family: any quadratic Hamiltonian ----

    def set_hamiltonian(self, lam: Any, f: Any = None) -> None:
        """Set H = 1/2 sum lambda_n |w_n|^2 + sum conj(f_n) w_n (n != 0).

        Every method, `energy`, the diagnostics and checkpoints use it; the
        state and the time are kept. Euler is lambda = 1/|n|^2, f = 0 (the
        default); SQG is 1/|n|, QG 1/(|n|^2 + k_d^2), Euler over a topography
        h is lambda = 1/|n|^2, f = -h/|n|^2 (see lpi_sine_euler_set_hamiltonian(3)).

        Parameters
        ----------
        lam : array_like of float
            N x N, in the modes' layout, symmetric (lambda_{-n} = lambda_n).
        f : array_like of complex, optional
            N x N, in the modes' layout, Hermitian (f_{-n} = conj(f_n));
            None for f = 0.

        Raises
        ------
        SizeError
            lam or f not N x N.
        NonFiniteError
            An entry is not finite.
        InvalidArgumentError
            lam not symmetric or f not Hermitian; nothing is changed.
        """
        lam_ptr, n_lam, _keep_lam = self._square_in(lam, "lam")
        f_ptr, n_f, _keep_f = None, 0, None
        if f is not None:
            f_ptr, n_f, _keep_f = self._square_in(f, "f", complex_=True)
        self._call("lpi_sine_euler_set_hamiltonian", lam_ptr, n_lam, f_ptr, n_f)

    def stream_function(self) -> Any:
        """The stream function psi = sum (lambda_n w_n + f_n) exp(i n.x) on the grid.

        Returns
        -------
        numpy.ndarray or list of list of float
            N x N real values, laid out as `grid`.
        """
        N = self.N
        if np is not None:
            out = np.empty((N, N), dtype=np.float64)
            self._call("lpi_sine_euler_get_stream", out.ctypes.data_as(_lib.c_double_p), N * N)
            return out
        buf = (c_double * (N * N))()
        self._call("lpi_sine_euler_get_stream", buf, N * N)
        return [list(buf[a * N:(a + 1) * N]) for a in range(N)]

    def spectrum(self) -> Tuple[ArrayOut, ArrayOut]:
        """Shell sums of the energy and enstrophy spectra.

        Shell k = 1 .. K holds the modes with k - 1/2 <= |n| < k + 1/2;
        the energy shells add up to H, the enstrophy shells to the
        enstrophy less 1/2 w_0^2.

        Returns
        -------
        tuple of (numpy.ndarray or list of float)
            (energy, enstrophy), K values each; entry k - 1 is shell k.
        """
        shells = c_size_t()
        self._call("lpi_sine_euler_spectrum", None, None, 0, byref(shells))  # a query of K
        energy_ptr, energy = _doubles_out(shells.value)
        enstrophy_ptr, enstrophy = _doubles_out(shells.value)
        self._call("lpi_sine_euler_spectrum", energy_ptr, enstrophy_ptr, shells.value, byref(shells))
        return energy(), enstrophy()


# ---- checkpoints ----------------------------------------------------------------

def load(path: PathLike) -> System:
    """A system restored from a checkpoint file (lpi_load).

    It continues the saved trajectory bit for bit, with the saved method and
    split.

    Parameters
    ----------
    path : str, bytes or os.PathLike
        The checkpoint file.

    Returns
    -------
    System
        A `RigidBody`, `Pendulum` or `SineEuler`.

    Raises
    ------
    FileError
        The file cannot be read (an `OSError`).
    FormatError
        Not a valid checkpoint (a `ValueError`).
    """
    handle = ctypes.c_void_p()
    _check_free(lib.lpi_load(byref(handle), _c_path(path)))
    return System._adopt(handle)


def _from_checkpoint(data: bytes, threads: int, planning: Optional[str] = None) -> System:
    """A system from checkpoint bytes with the thread count and FFTW planning
    of the system it was saved from (the checkpoint restores everything else;
    pickles without planning come from before it was kept)."""
    system = load_bytes(data)
    if threads != 1:
        system.threads = threads
    if planning is not None and planning != system.planning:
        system.planning = planning
    return system


def load_bytes(data: bytes) -> System:
    """A system restored from checkpoint bytes (lpi_load_buffer).

    Parameters
    ----------
    data : bytes-like
        What `System.save_bytes` returned.

    Returns
    -------
    System
        A `RigidBody`, `Pendulum` or `SineEuler`.

    Raises
    ------
    FormatError
        Not a valid checkpoint (a `ValueError`).
    """
    data = bytes(memoryview(data))  # bytes-like only: bytes(5) would be five zeros
    handle = ctypes.c_void_p()
    _check_free(lib.lpi_load_buffer(byref(handle), data, len(data)))
    return System._adopt(handle)


# ---- FFTW wisdom (process-wide) -----------------------------------------------

def fftw_wisdom_import_file(path: PathLike) -> None:
    """Import FFTW wisdom from a file (process-wide).

    Parameters
    ----------
    path : str, bytes or os.PathLike
        A file written by `fftw_wisdom_export_file`.
    """
    _check_free(lib.lpi_fftw_wisdom_import_file(_c_path(path)))


def fftw_wisdom_export_file(path: PathLike) -> None:
    """Export the process's FFTW wisdom to a file.

    Parameters
    ----------
    path : str, bytes or os.PathLike
        The file to write.
    """
    _check_free(lib.lpi_fftw_wisdom_export_file(_c_path(path)))


def fftw_wisdom_import_string(wisdom: str) -> None:
    """Import FFTW wisdom from a string (process-wide).

    Parameters
    ----------
    wisdom : str
        What `fftw_wisdom_export_string` returned.
    """
    _check_free(lib.lpi_fftw_wisdom_import_string(_c_string(wisdom, "wisdom")))


def fftw_wisdom_export_string() -> str:
    """The process's FFTW wisdom.

    Returns
    -------
    str
        The wisdom, for `fftw_wisdom_import_string`.
    """
    length = c_size_t()
    _check_free(lib.lpi_fftw_wisdom_export_string(None, 0, byref(length)))  # a query of the length
    # The wisdom is the process's: another thread planning between the query
    # and the copy adds to it, and the buffer is then made again at the new
    # length (given with LPI_ERR_SIZE).
    for _ in range(100):
        buf = ctypes.create_string_buffer(length.value + 1)
        status = lib.lpi_fftw_wisdom_export_string(buf, len(buf), byref(length))
        if status != STATUS["LPI_ERR_SIZE"]:
            break
    _check_free(status)
    return buf.value.decode()
