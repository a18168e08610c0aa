# SPDX-License-Identifier: MIT
"""Loading of the shared library rcal_ffi and its ctypes signatures.

The library is tools/host/outputs/rch_ffi.h compiled by python/CMakeLists.txt
(`pip install ./python` builds it with CMake and ships it inside the
package). It is found, in order, at the path in the environment variable
RCAL_FFI_LIB (an override), then next to this file (the installed package),
then in the build trees of the repository the package sits in
(build/python/librcal_ffi.so under the repository root, or any
<root>/build*/python/), for use from a source tree with PYTHONPATH=python.
"""

import ctypes
import glob
import os

ABI = 3  # RCH_FFI_ABI this package is written for
LIB_NAME = "librcal_ffi.so"

_c_double_p = ctypes.POINTER(ctypes.c_double)
_c_int_p = ctypes.POINTER(ctypes.c_int)
_c_size_p = ctypes.POINTER(ctypes.c_size_t)
_c_uint_p = ctypes.POINTER(ctypes.c_uint)

_lib = None


def repo_root():
    """The repository root: the parent of python/."""
    return os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _candidates():
    env = os.environ.get("RCAL_FFI_LIB")
    if env:
        return [env]
    root = repo_root()
    found = [os.path.join(os.path.dirname(os.path.abspath(__file__)), LIB_NAME)]
    found += [os.path.join(root, "build", "python", LIB_NAME)]
    found += sorted(glob.glob(os.path.join(root, "build*", "python", LIB_NAME)))
    return found


def _declare(lib):
    """Argument and result types of every rch_ffi_ function."""
    vp, cp, sz, d, i, u, ul = (ctypes.c_void_p, ctypes.c_char_p, ctypes.c_size_t, ctypes.c_double,
                              ctypes.c_int, ctypes.c_uint, ctypes.c_ulong)
    pvp = ctypes.POINTER(ctypes.c_void_p)
    ppc = ctypes.POINTER(ctypes.c_char_p)
    sigs = {
        "rch_ffi_abi": (i, []),
        "rch_ffi_strerror": (cp, [i]),
        "rch_ffi_model_load": (i, [pvp, cp, cp, sz]),
        "rch_ffi_model_free": (None, [vp]),
        "rch_ffi_model_name": (i, [vp, cp, sz]),
        "rch_ffi_model_has_nominal": (i, [vp]),
        "rch_ffi_model_limits": (i, [vp, _c_double_p, _c_double_p]),
        "rch_ffi_model_n_params": (u, [vp]),
        "rch_ffi_model_param": (i, [vp, u, i, cp, sz, _c_double_p, _c_int_p]),
        "rch_ffi_fk": (i, [vp, i, _c_double_p, _c_double_p, _c_double_p, sz, cp, sz]),
        "rch_ffi_cable_length": (i, [vp, _c_double_p, _c_double_p, sz, cp, sz]),
        "rch_ffi_version": (cp, []),
        "rch_ffi_lapack": (i, [cp, sz, _c_int_p, _c_int_p]),
        "rch_ffi_calibrate": (i, [pvp, ppc, sz, cp, cp, d, ul, u, cp, cp, u, cp, cp, ul, sz, cp, cp, cp, sz]),
        "rch_ffi_calibrate_arrays": (i, [pvp, _c_double_p, _c_double_p, _c_double_p, _c_int_p, _c_int_p, _c_int_p, sz,
                                         _c_double_p, sz, d, cp, cp, d, ul, u, cp, cp, u, cp, cp, ul, sz, cp, cp, cp,
                                         sz]),
        "rch_ffi_calibrate_inputs": (i, [pvp, ppc, sz, ppc, sz, _c_double_p, sz, d, cp, cp, d, ul, u, cp, cp, u, cp, cp,
                                         ul, sz, cp, cp, cp, sz]),
        "rch_ffi_calib_param_unc": (i, [vp, u, _c_double_p, _c_double_p, cp, sz, cp, sz, _c_int_p]),
        "rch_ffi_calib_get": (i, [vp, cp, _c_double_p]),
        "rch_ffi_calib_jumps": (i, [vp, _c_uint_p, _c_uint_p, _c_double_p, _c_double_p, u]),
        "rch_ffi_calib_outlets": (i, [vp, _c_uint_p, _c_int_p, u]),
        "rch_ffi_diagnose": (i, [pvp, cp, cp, ul, u, u, u, d, d, d, d, u, cp, sz]),
        "rch_ffi_diagnose_inputs": (i, [pvp, cp, cp, cp, cp, ul, u, u, u, d, d, d, d, u, cp, sz]),
        "rch_ffi_diag_free": (None, [vp]),
        "rch_ffi_diag_verdict": (i, [vp, cp, sz, _c_uint_p, cp, sz, cp, sz]),
        "rch_ffi_diag_chosen": (i, [vp, u, cp, sz, _c_double_p, _c_double_p, _c_double_p]),
        "rch_ffi_diag_param": (i, [vp, u, cp, sz, _c_double_p, _c_double_p, cp, sz]),
        "rch_ffi_diag_get": (i, [vp, cp, _c_double_p]),
        "rch_ffi_diag_next": (i, [vp, i, cp, sz]),
        "rch_ffi_diag_nuisance": (i, [vp, cp, sz]),
        "rch_ffi_diag_residuals": (i, [vp, _c_double_p, _c_double_p, _c_double_p]),
        "rch_ffi_diag_json": (i, [vp, cp, sz, _c_size_p]),
        "rch_ffi_diag_write": (i, [vp, cp, cp, sz]),
        "rch_ffi_evaluate": (i, [_c_double_p, vp, cp, i, d, cp, sz]),
        "rch_ffi_export": (i, [cp, cp, i, cp, i, _c_uint_p, _c_uint_p, cp, sz]),
        "rch_ffi_report": (i, [vp, vp, cp, cp, d, cp, sz, cp, sz]),
        "rch_ffi_calib_free": (None, [vp]),
        "rch_ffi_calib_metrics": (i, [vp, i, _c_double_p]),
        "rch_ffi_calib_info": (i, [vp, _c_size_p, _c_size_p, _c_int_p, _c_uint_p, _c_uint_p, cp, sz]),
        "rch_ffi_calib_n_params": (u, [vp]),
        "rch_ffi_calib_param": (i, [vp, u, cp, sz, _c_double_p, _c_double_p, _c_int_p]),
        "rch_ffi_calib_model": (i, [pvp, vp, cp, sz]),
        "rch_ffi_calib_write": (i, [vp, cp, cp, sz]),
        "rch_ffi_calib_truth": (i, [vp, _c_double_p]),
        "rch_ffi_calib_json": (i, [vp, cp, sz, _c_size_p]),
        "rch_ffi_compensate": (i, [vp, vp, _c_double_p, _c_int_p, _c_double_p, _c_double_p, sz, i, d, d, i,
                                   _c_double_p, cp, sz]),
        "rch_ffi_compensate_mode": (i, [vp, vp, i, d, _c_double_p, _c_double_p, cp, sz]),
    }
    for name, (res, args) in sigs.items():
        fn = getattr(lib, name)
        fn.restype = res
        fn.argtypes = args


def lib():
    """The loaded library (loaded once). Raises OSError naming every place
    tried when it is not found, or when its ABI is not the package's."""
    global _lib
    if _lib is not None:
        return _lib
    tried = []
    for path in _candidates():
        if not os.path.exists(path):
            tried.append(path)
            continue
        handle = ctypes.CDLL(path)
        handle.rch_ffi_abi.restype = ctypes.c_int
        handle.rch_ffi_abi.argtypes = []
        abi = handle.rch_ffi_abi()
        if abi != ABI:
            raise OSError("%s has rch_ffi ABI %d, this package needs %d: rebuild it (or reinstall the package)"
                          % (path, abi, ABI))
        _declare(handle)
        handle.rcal_path = path
        _lib = handle
        return _lib
    raise OSError("librcal_ffi.so not found (install the package: pip install --no-build-isolation ./python; "
                  "or build it, cmake --build build, or set RCAL_FFI_LIB to its path); tried: " + ", ".join(tried))
