"""Finding libliepoisson and declaring its C functions for ctypes.

The library is searched for in this order:
  1. the path in the environment variable LIEPOISSON_LIBRARY (final: a wrong
     path is an error, not a reason to look elsewhere);
  2. for a package installed by `make install`, the library installed with it
     (recorded in _install.py: relative to the package, then absolute);
  3. a build tree beside the sources (bindings/python/../../build);
  4. the system's library path (ctypes.util.find_library).
"""
import ctypes
import ctypes.util
import os
from ctypes import (CFUNCTYPE, POINTER, c_char_p, c_double, c_int, c_int32, c_int64,
                    c_size_t, c_void_p)

SONAME_MAJOR = 0

c_double_p = POINTER(c_double)
c_int32_p = POINTER(c_int32)
c_size_t_p = POINTER(c_size_t)
c_handle = c_void_p              # lpi_system * (opaque)
c_handle_p = POINTER(c_void_p)   # lpi_system **

# The callback types of include/liepoisson.h.
GRADIENT_FN = CFUNCTYPE(c_int, c_size_t, c_double_p, c_double_p, c_void_p)
ENERGY_FN = CFUNCTYPE(c_int, c_size_t, c_double_p, c_double_p, c_void_p)
CASIMIR_FN = CFUNCTYPE(c_int, c_size_t, c_double_p, c_double_p, c_void_p)
SCALAR_FN = CFUNCTYPE(c_int, c_double, c_double_p, c_void_p)
OBSERVER_FN = CFUNCTYPE(c_int, c_handle, c_int64, c_double, c_void_p)

# Every public function of include/liepoisson.h: name -> (restype, argtypes).
# A function added to the header gets one row here (tests/check_bindings.sh
# reports any that is missing).
PROTOTYPES = {
    # version, status codes, methods
    "lpi_version_string": (c_char_p, []),
    "lpi_version_number": (c_int, []),
    "lpi_status_name": (c_char_p, [c_int]),
    "lpi_status_message": (c_char_p, [c_int]),
    "lpi_method_count": (c_int, []),
    "lpi_method_name": (c_char_p, [c_int]),
    "lpi_method_order": (c_int, [c_int]),
    "lpi_method_is_poisson": (c_int, [c_int]),
    "lpi_method_stages": (c_int, [c_int]),
    "lpi_method_reference": (c_char_p, [c_int]),
    # systems
    "lpi_rigid_body_create": (c_int, [c_handle_p, c_double, c_double, c_double]),
    "lpi_rigid_body_exact": (c_int, [c_handle, c_double, c_double_p]),
    "lpi_pendulum_create": (c_int, [c_handle_p]),
    "lpi_destroy": (c_int, [c_handle]),
    "lpi_set_method": (c_int, [c_handle, c_char_p]),
    "lpi_set_split": (c_int, [c_handle, c_char_p]),
    "lpi_kind": (c_char_p, [c_handle]),
    "lpi_get_method": (c_char_p, [c_handle]),
    "lpi_get_split": (c_char_p, [c_handle]),
    "lpi_dim": (c_size_t, [c_handle]),
    "lpi_set_state": (c_int, [c_handle, c_double_p, c_size_t]),
    "lpi_get_state": (c_int, [c_handle, c_double_p, c_size_t]),
    "lpi_step": (c_int, [c_handle, c_double, c_int64]),
    "lpi_set_observer": (c_int, [c_handle, c_int64, OBSERVER_FN, c_void_p]),
    "lpi_time": (c_double, [c_handle]),
    "lpi_energy": (c_int, [c_handle, c_double_p]),
    "lpi_casimir_count": (c_size_t, [c_handle]),
    "lpi_casimirs": (c_int, [c_handle, c_double_p, c_size_t]),
    "lpi_last_error": (c_char_p, [c_handle]),
    # composition methods, implicit baselines
    "lpi_set_composition": (c_int, [c_handle, c_size_t, c_double_p]),
    "lpi_flows_per_step": (c_int, [c_handle, c_size_t_p]),
    "lpi_set_implicit_options": (c_int, [c_handle, c_double, c_int32]),
    # generic systems and the moment algebra
    "lpi_generic_create": (c_int, [c_handle_p, c_size_t, c_size_t, c_int32_p, c_int32_p,
                                   c_int32_p, c_double_p]),
    "lpi_add_piece": (c_int, [c_handle, c_size_t, c_int32_p, GRADIENT_FN, ENERGY_FN, c_void_p]),
    "lpi_add_casimir": (c_int, [c_handle, CASIMIR_FN, c_void_p]),
    "lpi_poisson_rank": (c_int, [c_handle, c_double_p, c_size_t, c_size_t_p]),
    "lpi_moments_create": (c_int, [c_handle_p]),
    "lpi_moments_add_product_piece": (c_int, [c_handle, SCALAR_FN, SCALAR_FN, c_void_p]),
    # sine-Euler, threads, FFTW wisdom
    "lpi_sine_euler_create": (c_int, [c_handle_p, c_int32]),
    "lpi_sine_euler_size": (c_int, [c_handle, c_int32_p]),
    "lpi_sine_euler_set_modes": (c_int, [c_handle, c_double_p, c_size_t]),
    "lpi_sine_euler_get_modes": (c_int, [c_handle, c_double_p, c_size_t]),
    "lpi_sine_euler_set_grid": (c_int, [c_handle, c_double_p, c_size_t]),
    "lpi_sine_euler_get_grid": (c_int, [c_handle, c_double_p, c_size_t]),
    "lpi_sine_euler_enstrophy": (c_int, [c_handle, c_double_p]),
    "lpi_sine_euler_casimir_traces": (c_int, [c_handle, c_int32, c_double_p]),
    "lpi_sine_euler_fft_floor": (c_int, [c_handle, c_int64, c_double_p, c_double_p]),
    "lpi_sine_euler_set_planning": (c_int, [c_handle, c_char_p]),
    "lpi_sine_euler_get_planning": (c_int, [c_handle, POINTER(c_char_p)]),
    "lpi_sine_euler_set_hamiltonian": (c_int, [c_handle, c_double_p, c_size_t, c_double_p, c_size_t]),
    "lpi_sine_euler_get_stream": (c_int, [c_handle, c_double_p, c_size_t]),
    "lpi_sine_euler_spectrum": (c_int, [c_handle, c_double_p, c_double_p, c_size_t, c_size_t_p]),
    "lpi_set_threads": (c_int, [c_handle, c_int32]),
    "lpi_fftw_wisdom_import_file": (c_int, [c_char_p]),
    "lpi_fftw_wisdom_export_file": (c_int, [c_char_p]),
    "lpi_fftw_wisdom_import_string": (c_int, [c_char_p]),
    "lpi_fftw_wisdom_export_string": (c_int, [c_char_p, c_size_t, c_size_t_p]),
    "lpi_save": (c_int, [c_handle, c_char_p]),
    "lpi_load": (c_int, [c_handle_p, c_char_p]),
    "lpi_save_buffer": (c_int, [c_handle, c_void_p, c_size_t, c_size_t_p]),
    "lpi_load_buffer": (c_int, [c_handle_p, c_void_p, c_size_t]),
}


def _candidates():
    env = os.environ.get("LIEPOISSON_LIBRARY")
    if env:
        # An explicit choice is final: a wrong path is an error, not a fallback.
        yield env
        return
    here = os.path.dirname(os.path.abspath(__file__))
    try:
        from . import _install
    except ImportError:  # not installed by make install
        pass
    else:
        yield os.path.normpath(os.path.join(here, _install.LIBRARY_RELATIVE))
        yield _install.LIBRARY
    for build in (os.path.join(here, "..", "..", "..", "build"),):
        yield os.path.normpath(os.path.join(build, "libliepoisson.so.%d" % SONAME_MAJOR))
    found = ctypes.util.find_library("liepoisson")
    if found:
        yield found
    yield "libliepoisson.so.%d" % SONAME_MAJOR


def _load():
    tried = []
    env = os.environ.get("LIEPOISSON_LIBRARY")
    for path in _candidates():
        if os.sep in path and not os.path.exists(path) and not env:
            tried.append(path + " (absent)")
            continue
        try:
            return ctypes.CDLL(path)
        except OSError as e:
            tried.append("%s (%s)" % (path, e))
    raise ImportError("liepoisson: cannot load libliepoisson; set LIEPOISSON_LIBRARY to its path. "
                      "Tried: " + "; ".join(tried))


def _declare(lib):
    missing = []
    for name, (restype, argtypes) in PROTOTYPES.items():
        try:
            fn = getattr(lib, name)
        except AttributeError:
            missing.append(name)
            continue
        fn.restype = restype
        fn.argtypes = argtypes
    return missing


lib = _load()
# The binding is released with the library and calls every function it
# declares: a library that lacks one (an older build found first on the
# path) is refused here, by name, rather than failing later in some call.
_missing = _declare(lib)
if _missing:
    _named = ", ".join(_missing[:4]) + (" and %d more" % (len(_missing) - 4) if len(_missing) > 4 else "")
    raise ImportError("liepoisson: the library %s lacks %s, which this binding needs (an older "
                      "libliepoisson?); set LIEPOISSON_LIBRARY to the library built with it"
                      % (lib._name, _named))
