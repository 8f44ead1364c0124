"""Where a result was computed (floor 0): ``env.json`` beside ``meta.json``.

``meta.json`` holds only what the config and the seed fix, so it is byte-identical on a rerun in
any fresh environment. The environment goes to ``env.json``, which -- like ``timing.csv`` --
changes with the machine and is never compared by ``fkopt check``:

* ``fkopt_version`` and ``libraries`` (Python and the versions of the libraries fkopt uses);
* ``platform`` (operating system, CPU architecture, CPU model);
* ``numerics`` -- which numerics path made the result (``path``: ``"compiled"`` or ``"numpy"``),
  the ``FKOPT_NUMERICS`` mode it ran under and numba's version
  (:func:`fkopt.numerics.path.describe`); ``fkopt check`` reruns under that mode
  (:func:`fkopt.numerics.path.forced`). Not part of the fingerprint: one-pose inverse answers
  are the same on both paths, and so are the 3-RPS swarm runs, compiled by default around
  numpy's own ``np.tan`` (tests/test_numerics.py);
* ``fingerprint`` -- what decides the bits of a result, in two parts (:data:`BLAS_KEYS`):

  - the arithmetic fkopt's own elementwise code runs: Python, numpy, scipy and pandas versions,
    the CPU architecture and the SIMD targets numpy dispatches to on this CPU (``numpy_simd``:
    its baseline and dispatch targets that the CPU supports; numpy picks its ufunc loops by them);
  - the BLAS/LAPACK that ``np.linalg`` and matrix products call: the build numpy was linked with
    (``blas``) and what runs (``blas_runtime``: library, version, the kernel OpenBLAS picked for
    this CPU -- threadpoolctl's ``architecture``, which ``OPENBLAS_CORETYPE`` can force -- and
    the thread count), for numpy's and scipy's copies.

  The CPU model string is *not* part of it (a virtual machine may report only "Intel(R) Xeon(R)
  Processor"); what it decides is named above. :func:`platform_tier` says which part of a stored
  fingerprint differs from this machine's, and :mod:`fkopt.run.compare` picks its rules by that.
"""
from __future__ import annotations

import platform
import sys
from functools import lru_cache

import fkopt
from fkopt.files.host import installed_version
from fkopt.numerics import path as numerics_path

ENV_FILE = "env.json"
LIBRARIES = ("numpy", "scipy", "pandas", "matplotlib", "pydantic", "pyyaml", "typer", "rich", "pymoo", "niapy",
             "yourdfpy")


def library_versions() -> dict[str, str]:
    out = {"python": sys.version.split()[0]}
    for lib in LIBRARIES:
        if (got := installed_version(lib)) is not None:
            out[lib] = got
    return out


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def _blas() -> str:
    try:
        import numpy as np
        deps = np.show_config(mode="dicts")["Build Dependencies"]
        blas, lapack = deps.get("blas", {}), deps.get("lapack", {})
        return f"blas {blas.get('name')} {blas.get('version')}; lapack {lapack.get('name')} {lapack.get('version')}"
    except Exception:   # older numpy without mode="dicts": the fingerprint just says so
        return "unknown"


def _numpy_simd() -> str:
    """The SIMD targets numpy's ufunc loops dispatch to here: its baseline and dispatch targets
    that this CPU supports (``NPY_DISABLE_CPU_FEATURES`` included, as numpy applies it)."""
    try:
        from numpy._core._multiarray_umath import __cpu_baseline__, __cpu_dispatch__, __cpu_features__
    except ImportError:   # numpy < 2
        try:
            from numpy.core._multiarray_umath import __cpu_baseline__, __cpu_dispatch__, __cpu_features__
        except ImportError:
            return "unknown"
    return " ".join(t for t in [*__cpu_baseline__, *__cpu_dispatch__] if __cpu_features__.get(t))


def _blas_runtime() -> str:
    """The BLAS libraries loaded by numpy and scipy.linalg, with the kernel each runs (threadpoolctl)."""
    try:
        import numpy  # noqa: F401
        import scipy.linalg  # noqa: F401
        from threadpoolctl import threadpool_info
    except ImportError:
        return "unknown"
    libs = sorted({f"{i.get('internal_api')} {i.get('version')} kernel={i.get('architecture')} "
                   f"threads={i.get('num_threads')} {i.get('threading_layer')}"
                   for i in threadpool_info() if i.get("user_api") == "blas"})
    return "; ".join(libs) or "none"


#: The fingerprint's BLAS part; the rest decides the bits of fkopt's own elementwise arithmetic.
BLAS_KEYS = ("blas", "blas_runtime")
EXACT, BLAS, ANY = "exact", "blas", "any"


@lru_cache(maxsize=1)
def fingerprint() -> dict[str, str]:
    """What decides the bits of a result on this machine (see the module docstring)."""
    libs = library_versions()
    return {"python": libs["python"], "numpy": libs.get("numpy", "?"), "scipy": libs.get("scipy", "?"),
            "pandas": libs.get("pandas", "?"), "machine": platform.machine(), "numpy_simd": _numpy_simd(),
            "blas": _blas(), "blas_runtime": _blas_runtime()}


def platform_tier(stored) -> str:
    """How a result stored with fingerprint ``stored`` compares on this machine:

    * ``"exact"`` -- the same fingerprint: every deterministic file byte for byte;
    * ``"blas"`` -- only the BLAS part differs: results no BLAS call touches are still exact, the
      rest follows :mod:`fkopt.run.compare`'s cross-platform rules;
    * ``"any"`` -- the elementwise part differs too (another numpy, SIMD target set, Python...),
      or the stored fingerprint is missing or of an older form: the cross-platform rules for all.
    """
    here = fingerprint()
    if not isinstance(stored, dict):
        return ANY
    if stored == here:
        return EXACT
    differ = {k for k in set(stored) | set(here) if stored.get(k) != here.get(k)}
    return BLAS if differ <= set(BLAS_KEYS) else ANY


def environment() -> dict:
    """The contents of ``env.json``."""
    return {"fkopt_version": fkopt.__version__, "libraries": library_versions(),
            "platform": {"system": platform.system(), "machine": platform.machine(),
                         "python_implementation": platform.python_implementation(), "cpu": _cpu_model()},
            "fingerprint": fingerprint(), "numerics": numerics_path.describe()}
