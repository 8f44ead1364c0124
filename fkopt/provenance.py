"""Where a result was computed (floor 0): ``env.json`` beside ``meta.json``.

``meta.json`` holds only what the config and the seed fix, so it is byte-identical on a rerun in
any fresh environment. The environment goes to ``env.json``, which -- like ``timing.csv`` --
changes with the machine and is never compared by ``fkopt check``:

* ``fkopt_version`` and ``libraries`` (Python and the versions of the libraries fkopt uses);
* ``platform`` (operating system, CPU architecture, CPU model);
* ``fingerprint`` -- the part that decides whether floating-point results can be expected to be
  bit-identical: Python, numpy, scipy and pandas versions, the BLAS/LAPACK build numpy uses, the
  CPU architecture and the CPU model (OpenBLAS picks its kernels by CPU at run time).
  ``fkopt check`` compares every deterministic file byte for byte when the stored fingerprint
  equals this machine's, and by distribution-level tolerances otherwise (:mod:`fkopt.compare`).
"""
from __future__ import annotations

import platform
import sys
from functools import lru_cache
from importlib.metadata import PackageNotFoundError, version

ENV_FILE = "env.json"
LIBRARIES = ("numpy", "scipy", "pandas", "matplotlib", "pydantic", "pyyaml", "typer", "rich", "pymoo", "niapy",
             "yourdfpy")


def library_versions() -> dict[str, str]:
    out = {"python": sys.version.split()[0]}
    for lib in LIBRARIES:
        try:
            out[lib] = version(lib)
        except PackageNotFoundError:
            pass
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


@lru_cache(maxsize=1)
def fingerprint() -> dict[str, str]:
    """Python, numpy, scipy, pandas, BLAS/LAPACK build, CPU architecture and model of this machine."""
    libs = library_versions()
    return {"python": libs["python"], "numpy": libs.get("numpy", "?"), "scipy": libs.get("scipy", "?"),
            "pandas": libs.get("pandas", "?"), "blas": _blas(), "machine": platform.machine(),
            "cpu": _cpu_model()}


def environment() -> dict:
    """The contents of ``env.json``."""
    try:
        fkopt_version = version("fkopt")
    except PackageNotFoundError:
        fkopt_version = "0.0.0+unknown"
    return {"fkopt_version": fkopt_version, "libraries": library_versions(),
            "platform": {"system": platform.system(), "machine": platform.machine(),
                         "python_implementation": platform.python_implementation(), "cpu": _cpu_model()},
            "fingerprint": fingerprint()}
