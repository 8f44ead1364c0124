"""The compiled reference of sections ``cases`` and ``swarms``: the same GABC, ABC and PSO on the
same 3-RPS fitness as a plain C loop (``ref/gabc_3rps.c``, one run after the other), compiled
with the system's C compiler into a temporary folder when the bench runs."""
from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np

#: The compiled reference of sections ``cases`` and ``swarms``: the same GABC (ABC, PSO) on the same
#: 3-RPS fitness as a plain C loop (one run after the other), compiled with the system's C compiler
#: when the bench runs.
REFERENCE_C = Path(__file__).parent / "ref" / "gabc_3rps.c"
#: Compiler flags tried in order (the first that compiles is used).
REFERENCE_FLAGS = (("-O3", "-march=native"), ("-O2",))


def compile_reference(folder: Path) -> tuple[Path, str] | str:
    """Compile :data:`REFERENCE_C` into ``folder``: (executable, compiler command), or a message
    saying why not (no compiler: ``$CC``, ``gcc``, ``cc`` or ``clang`` on the PATH; errors)."""
    cc = os.environ.get("CC") or next((c for c in ("gcc", "cc", "clang") if shutil.which(c)), None)
    if cc is None or shutil.which(cc.split()[0]) is None:
        return "no C compiler ($CC, gcc, cc or clang) on the PATH"
    exe = folder / "gabc_3rps"
    err = ""
    for flags in REFERENCE_FLAGS:
        cmd = [*cc.split(), *flags, "-o", str(exe), str(REFERENCE_C), "-lm"]
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
        except (OSError, subprocess.SubprocessError) as e:
            return f"{cc} failed to run: {e}"
        if p.returncode == 0:
            return exe, " ".join([cc, *flags])
        err = (p.stderr.strip().splitlines() or ["(no message)"])[-1]
    return f"{cc} could not compile {REFERENCE_C.name}: {err}"


def run_reference(exe: Path, joints: np.ndarray, iterations: int, population: int, runs: int,
                  seed: int = 1, algorithm: str = "gabc") -> dict[str, float]:
    """Solve every row of ``joints`` (cases, 3) ``runs`` times with the compiled loop of
    ``algorithm`` (gabc, abc or pso): evaluations, seconds and cpu_seconds (of the solves, wall
    and CPU time, timed inside the program), median and largest final fitness."""
    data = "\n".join(" ".join(repr(float(v)) for v in row) for row in np.atleast_2d(joints)) + "\n"
    p = subprocess.run([str(exe), str(iterations), str(population), str(runs), str(seed), algorithm], input=data,
                       capture_output=True, text=True, timeout=1800, check=True)
    evals, seconds, median, worst, cpu = p.stdout.split()
    return {"evaluations": float(evals), "seconds": float(seconds), "median": float(median),
            "worst": float(worst), "cpu_seconds": float(cpu)}
