"""``fkopt bench``: measure fkopt's speed on this machine (and, optionally, peers' speed). This
module runs the sections and prints and writes their table (``bench.csv``: columns section,
item, value, unit, note); each section is a module of its own:

=================  ===========================================================================
section            module
=================  ===========================================================================
``throughput``     :mod:`.throughput` -- batched fitness evaluations per second, every mechanism
``mao2017``        :mod:`.paper_times` -- mao2017's Tab. 3 experiment beside the paper's times
``peers``          :mod:`.peer_abc` -- NiaPy's, MEALPY's, pygmo's and npEA's ABC on the same
                   fitness (``peers=True``)
``adapters``       :mod:`.library_adapters` -- scipy's, pymoo's and NiaPy's DE through fkopt's
                   adapters (``peers=True`` or named)
``exact``          :mod:`.exact_batch` -- 1000 6-SPS poses solved by the batched ``lm``
``kinematics``     :mod:`.exact_kinematics` -- ``fkopt.forward``, ``fkopt.inverse``, all
                   solutions, the ``fkopt fk`` process; rtb's ``ik_LM``
``ik-one-pose``    :mod:`.ik_one_pose` -- real arms beside rtb, one pose per call
``ik-batch``       :mod:`.ik_batch` -- real arms beside rtb, 1000 poses in one call
``cases``          :mod:`.cases` -- N cases x 30 runs together, beside a C loop
``swarms``         :mod:`.swarms` -- GABC, ABC, PSO beside the C loop; pygmo's bee_colony
``fksgp``          :mod:`.fksgp` -- all 40 FK solutions of general 6-6 platforms beside fkSGP
``scaling``        :mod:`.scaling` -- population and runs; ``scaling.png``
=================  ===========================================================================

:mod:`.measuring` holds what they all measure with (the rows, call timers, the load average),
:mod:`.ik_arms` the arms of the two IK sections, :mod:`.c_reference` the C loop of ``cases`` and
``swarms``. Timings are wall-clock on whatever else the machine is doing; every section notes the
load average before and after it; tests never assert them.
"""
from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pandas as pd
from rich.console import Console
from rich.table import Table

from fkopt.tools.bench.cases import bench_cases
from fkopt.tools.bench.exact_batch import bench_exact
from fkopt.tools.bench.exact_kinematics import bench_cli_process, bench_kinematics
from fkopt.tools.bench.fksgp import bench_fksgp
from fkopt.tools.bench.ik_batch import bench_ik_batch
from fkopt.tools.bench.ik_one_pose import bench_ik_one_pose
from fkopt.tools.bench.library_adapters import bench_adapters
from fkopt.tools.bench.measuring import Rows, load_average, machine
from fkopt.tools.bench.paper_times import bench_mao2017
from fkopt.tools.bench.peer_abc import bench_peers
from fkopt.tools.bench.scaling import bench_scaling, plot_scaling
from fkopt.tools.bench.swarms import bench_pygmo_abc, bench_swarms
from fkopt.tools.bench.throughput import bench_throughput
from fkopt.files import inside


def _fmt(v: float) -> str:
    if v == 0 or not np.isfinite(v):
        return f"{v:g}"
    if abs(v) >= 1e5 or abs(v) < 1e-3:
        return f"{v:.3e}"
    return f"{v:.4g}"


SECTIONS = ("throughput", "mao2017", "peers", "adapters", "exact", "kinematics", "ik-one-pose", "ik-batch",
            "cases", "swarms", "fksgp", "scaling")


def run(quick: bool = False, peers: bool = False, out="bench", sections=None) -> pd.DataFrame:
    """Run the benchmark; print a table, write ``out/bench.csv`` and ``out/scaling.png``.

    ``sections``: names from :data:`SECTIONS` to run (default all; ``peers`` also needs
    ``peers=True`` or its name here). ``scaling.png`` is written only with the scaling section."""
    want = set(sections or SECTIONS)
    console = Console()
    if not console.is_terminal:   # files and pipes: wide enough for the notes
        console = Console(width=200)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    for name in ("bench.csv", "scaling.png"):     # no write through a link, checked before measuring
        inside(out, out / name)
    rng = np.random.default_rng(20240601)
    rows = Rows()
    messages: list[str] = []
    start = time.perf_counter()

    spent: dict[str, float] = {}                       # seconds per section, printed at the end

    def timed(name, fn, *args):
        before = load_average()
        t = time.perf_counter()
        got = fn(*args)
        spent[name] = spent.get(name, 0.0) + time.perf_counter() - t
        after = load_average()
        try:
            value = float(after.split()[0])
        except ValueError:                           # pragma: no cover - no load average here
            value = float("nan")
        rows.add(name, "load average", value, "", f"1/5/15-min load average before the section {before}, after "
                 f"{after} ({os.cpu_count()} CPUs): timings here are wall clock on a shared machine; read the ratios")
        return got

    if "throughput" in want:
        timed("throughput", bench_throughput, rows, quick, rng)
    per_run = timed("mao2017", bench_mao2017, rows, quick) if ("mao2017" in want or "peers" in want) else {}
    if peers and "peers" in want:
        timed("peers", bench_peers, rows, quick, per_run.get("gabc"), messages)
    if (peers or sections) and "adapters" in want:       # opt-in, as peers: needs pymoo/NiaPy
        timed("adapters", bench_adapters, rows, quick, messages)
    if "exact" in want:
        timed("exact", bench_exact, rows, quick, rng)
    if "kinematics" in want:
        timed("kinematics", bench_kinematics, rows, quick, np.random.default_rng(12), messages)
        timed("kinematics", bench_cli_process, rows, quick)
    if "ik-one-pose" in want:
        timed("ik-one-pose", bench_ik_one_pose, rows, quick, messages)
    if "ik-batch" in want:
        timed("ik-batch", bench_ik_batch, rows, quick, messages)
    if "cases" in want:
        timed("cases", bench_cases, rows, quick, rng, messages)
    if "swarms" in want:
        timed("swarms", bench_swarms, rows, quick, np.random.default_rng(29), messages)
        timed("swarms", bench_pygmo_abc, rows, quick, messages)
    if "fksgp" in want:                                  # skipped with a message without the vendored fkSGP
        timed("fksgp", bench_fksgp, rows, quick, messages)
    if "scaling" in want:
        curves = timed("scaling", bench_scaling, rows, quick)
        plot_scaling(curves, out / "scaling.png", 50 if quick else 200)

    df = pd.DataFrame(rows.rows, columns=["section", "item", "value", "unit", "note"])
    df.to_csv(out / "bench.csv", index=False)

    info = machine()
    table = Table(title=f"fkopt bench{' (quick)' if quick else ''}: {info['cpus']} CPUs, {info['cpu']}, "
                        f"numpy {info['numpy']}")
    for col in ("section", "item", "value", "unit", "note"):
        table.add_column(col, justify="right" if col == "value" else "left")
    for r in rows.rows:
        table.add_row(r["section"], r["item"], _fmt(r["value"]), r["unit"], r["note"])
    console.print(table)
    for msg in messages:
        console.print(msg)
    wrote = f"{out / 'bench.csv'}" + (f" and {out / 'scaling.png'}" if "scaling" in want else "")
    per = ", ".join(f"{k} {v:.1f}" for k, v in spent.items())
    console.print(f"total {time.perf_counter() - start:.1f} s ({per}); wrote {wrote}")
    return df
