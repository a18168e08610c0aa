# SPDX-License-Identifier: MIT
"""The package installed as a user installs it, then used (ctest
python_venv_install).

    python3 venv_install.py RCAL_BIN SOURCE_ROOT [--demo-only]

1. a clean virtual environment (`python3 -m venv --system-site-packages`,
   so that the system's numpy, setuptools and wheel are there: the machine
   may be offline);
2. `pip install --no-build-isolation <copy of python/>` with RCAL_SOURCE_DIR
   set to the repository (a copy, so the test writes nothing into the source
   tree; `pip install ./python` from a clone finds the root by itself),
   with no RCAL_FFI_LIB in the environment: pip's build runs CMake on the
   repository for the rcal_ffi target and ships librcal_ffi.so inside the
   package;
3. from outside the source tree, the installed package must load its own
   library, report __version__, and pass session_check.py (calibrate,
   diagnose, compensate equal to the CLI);
4. the wheel of the same source installed into a virtual environment with
   nothing in it (no system site packages: no numpy, setuptools, wheel), and
   session_check.py --demo-only there;
5. in both environments, `ldd` of the installed librcal_ffi.so names no
   LAPACK, BLAS or Fortran run-time (liblapack*, libblas*, libatlas*,
   libopenblas*, lapacke, libgfortran*, libquadmath*): the reference archives
   are linked in, so the wheel runs where none is installed (issue 52).
--demo-only (passed on to session_check.py) checks the demo data only. Exit 77 (ctest: skipped) with the reason when venv or pip
is unavailable.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time


def skip(why):
    print("python_venv_install: SKIPPED: " + why)
    sys.exit(77)


FOREIGN = re.compile(r"^(liblapack|libblas|libatlas|libopenblas|liblapacke|libgfortran|libquadmath|libcblas|libptcblas|"
                     r"libf77blas)")


def check_ldd(py, env, cwd, where):
    """5. The installed extension needs no LAPACK, BLAS or Fortran library
    from the loader. 0 when so (the libraries it needs printed), else 1."""
    p = subprocess.run([py, "-c", "import rcal; print(rcal.library_path())"], cwd=cwd, env=env, capture_output=True,
                       text=True)
    lib = p.stdout.strip()
    if p.returncode != 0 or not os.path.isfile(lib):
        print("python_venv_install: FAILED: %s: rcal.library_path() %r (%s)" % (where, lib, p.stderr.strip()))
        return 1
    if shutil.which("ldd") is None:
        print("python_venv_install: %s: no ldd on this machine; the library check is left out" % where)
        return 0
    p = subprocess.run(["ldd", lib], capture_output=True, text=True)
    needed = [ln.split()[0] for ln in p.stdout.splitlines() if ln.strip()]
    foreign = [n for n in needed if FOREIGN.match(os.path.basename(n))]
    print("%s: ldd %s: %s" % (where, os.path.basename(lib), " ".join(needed)))
    if p.returncode != 0 or foreign:
        print("python_venv_install: FAILED: %s: the extension needs %s from the loader" % (where, foreign or p.stderr))
        return 1
    return 0


def clean_wheel(py, src, tmp, env, rcal_bin, root):
    """4. The wheel (pip wheel, as the python_wheel target builds it) into a
    virtual environment with nothing in it: no system site packages, so no
    numpy, setuptools or wheel; the demo session must still equal the CLI."""
    dist = os.path.join(tmp, "dist")
    t0 = time.time()
    p = subprocess.run([py, "-m", "pip", "wheel", "--no-build-isolation", "--no-deps", "--no-index", "-w", dist, src],
                       cwd=tmp, env=env, capture_output=True, text=True)
    wheels = [f for f in os.listdir(dist) if f.endswith(".whl")] if os.path.isdir(dist) else []
    if p.returncode != 0 or len(wheels) != 1:
        print(p.stdout[-4000:], p.stderr[-4000:])
        print("python_venv_install: FAILED: pip wheel ./python")
        return 1
    clean = os.path.join(tmp, "clean")
    p = subprocess.run([sys.executable, "-m", "venv", clean], capture_output=True, text=True)
    if p.returncode != 0:
        print("python_venv_install: FAILED: python3 -m venv (no system site packages): " + p.stderr.strip())
        return 1
    cpy = os.path.join(clean, "bin", "python")
    bare = subprocess.run([cpy, "-c", "import importlib.util as u; print([m for m in ('numpy', 'wheel') "
                                      "if u.find_spec(m)])"], capture_output=True, text=True).stdout.strip()
    p = subprocess.run([cpy, "-m", "pip", "install", "--no-deps", "--no-index", os.path.join(dist, wheels[0])],
                       cwd=tmp, env=env, capture_output=True, text=True)
    t1 = time.time()
    if p.returncode != 0:
        print(p.stdout[-4000:], p.stderr[-4000:])
        print("python_venv_install: FAILED: pip install of the wheel into a clean environment")
        return 1
    print("clean environment (importable of numpy, wheel: %s): %s installed in %.1f s (wheel build included)" % (
        bare, wheels[0], t1 - t0))
    if check_ldd(cpy, env, tmp, "clean environment (wheel)") != 0:
        return 1
    p = subprocess.run([cpy, os.path.join(root, "python", "tests", "session_check.py"), rcal_bin, root,
                        os.path.join(tmp, "work_clean"), "--demo-only"], cwd=tmp, env=env, capture_output=True,
                       text=True)
    print(p.stdout + p.stderr)
    return p.returncode


def main(argv):
    rcal_bin, root = os.path.abspath(argv[1]), os.path.abspath(argv[2])
    try:
        import venv  # noqa: F401
        import ensurepip  # noqa: F401
    except ImportError as e:
        skip("%s has no venv/ensurepip (%s; Debian: apt-get install python3-venv)" % (sys.executable, e))
    tmp = tempfile.mkdtemp(prefix="rcal-venv-")
    env = {k: v for k, v in os.environ.items() if k not in ("RCAL_FFI_LIB", "PYTHONPATH", "LD_PRELOAD")}
    try:
        t0 = time.time()
        env_dir = os.path.join(tmp, "venv")
        p = subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", env_dir], capture_output=True,
                           text=True)
        if p.returncode != 0:
            skip("python3 -m venv failed (%s)" % p.stderr.strip().splitlines()[-1:])
        py = os.path.join(env_dir, "bin", "python")
        if subprocess.run([py, "-m", "pip", "--version"], capture_output=True).returncode != 0:
            skip("pip is not available in the virtual environment (Debian: apt-get install python3-pip)")
        missing = subprocess.run([py, "-c", "import setuptools, wheel"], capture_output=True).returncode != 0
        if missing:
            skip("setuptools or wheel is missing (Debian: python3-setuptools, python3-wheel); offline, pip cannot "
                 "fetch them")
        src = os.path.join(tmp, "python")
        shutil.copytree(os.path.join(root, "python"), src,
                        ignore=shutil.ignore_patterns("build", "*.egg-info", "dist", "__pycache__"))
        env["RCAL_SOURCE_DIR"] = root
        t1 = time.time()
        p = subprocess.run([py, "-m", "pip", "install", "--no-build-isolation", "--no-deps", "--no-index", src],
                           cwd=tmp, env=env, capture_output=True, text=True)
        t2 = time.time()
        if p.returncode != 0:
            print(p.stdout[-4000:], p.stderr[-4000:])
            print("python_venv_install: FAILED: pip install --no-build-isolation ./python")
            return 1
        print("venv %.1f s, pip install --no-build-isolation ./python %.1f s (CMake build of librcal_ffi.so "
              "included)" % (t1 - t0, t2 - t1))
        probe = ("import os, rcal, sys; p = rcal.library_path(); print(rcal.__version__, p, rcal.default_robot()); "
                 "sys.exit(0 if p.startswith(sys.prefix) and os.path.dirname(p) == os.path.dirname(rcal.__file__) "
                 "and rcal.default_robot().startswith(sys.prefix) else 1)")
        p = subprocess.run([py, "-c", probe], cwd=tmp, env=env, capture_output=True, text=True)
        print("installed: " + (p.stdout.strip() or p.stderr.strip()))
        if p.returncode != 0:
            print("python_venv_install: FAILED: the installed package does not use its own library and data")
            return 1
        if check_ldd(py, env, tmp, "venv (pip install ./python)") != 0:
            return 1
        p = subprocess.run([py, os.path.join(root, "python", "tests", "session_check.py"), rcal_bin, root,
                            os.path.join(tmp, "work")] + argv[3:], cwd=tmp, env=env, capture_output=True, text=True)
        print(p.stdout + p.stderr)
        if p.returncode != 0:
            print("python_venv_install: FAILED in %.1f s" % (time.time() - t0))
            return p.returncode
        rc = clean_wheel(py, src, tmp, env, rcal_bin, root)
        print("python_venv_install: %s in %.1f s" % ("passed" if rc == 0 else "FAILED", time.time() - t0))
        return rc
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
