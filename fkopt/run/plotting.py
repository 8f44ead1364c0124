"""One plotting style for every figure fkopt writes (experiments, studies, reports).

Publication rules applied everywhere:

* algorithms are named as the papers name them (:func:`algorithm_name`), never by internal labels;
* axes carry units (:func:`fitness_label`);
* a fitness of exactly 0 cannot sit on a log axis: values below the figure's floor (a decade under
  its smallest positive value, at least :data:`MIN_FLOOR`) are drawn *at* the floor, and a grey
  band labelled "0 (exact)" marks that floor, so zero is never confused with a tiny number;
* independent cases (poses) are markers, never joined by lines;
* files are written as PNG and, beside it, PDF (vector) with metadata that carries no version or
  date, so a rerun writes byte-identical files where the libraries allow it.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from fkopt.registry import solver_entry

#: Lowest floor used to draw exact zeros on a log axis.
MIN_FLOOR = 1e-30



def _display(method: str, fallback: str) -> str:
    """A solver's display name from the registry (the names the papers use), else ``fallback``."""
    entry = solver_entry(method)
    return entry.display if entry is not None and entry.display else fallback


def plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as pyplot
    pyplot.rcParams.update({
        "figure.dpi": 150, "savefig.dpi": 150, "font.size": 9, "axes.titlesize": 9, "axes.labelsize": 9,
        "legend.fontsize": 8, "legend.frameon": False, "axes.spines.top": False, "axes.spines.right": False,
        "axes.grid": True, "grid.alpha": 0.3, "lines.linewidth": 1.4, "svg.hashsalt": "fkopt",
        "pdf.fonttype": 42,
    })
    return pyplot


def save(fig, path: Path, vector: bool = True) -> list[str]:
    """Write ``path`` (PNG) and its PDF twin, without version or date metadata; returns the names."""
    path = Path(path)
    fig.savefig(path, metadata={"Software": None}, bbox_inches="tight")
    names = [path.name]
    if vector:
        pdf = path.with_suffix(".pdf")
        fig.savefig(pdf, metadata={"Creator": None, "Producer": None, "CreationDate": None, "ModDate": None},
                    bbox_inches="tight")
        names.append(pdf.name)
    return names


def algorithm_name(method: str, params: dict | None = None, label: str | None = None) -> str:
    """The paper's name of a configured algorithm: method, GABC rule, selection, hybrids."""
    params = params or {}
    if "+" in method:
        return "+".join(_display(m, m.upper()) for m in method.split("+"))
    name = _display(method, method)
    if method == "gabc":
        name = "GABC (Zhu & Kwong)" if params.get("rule") == "zhu2010" else "GABC (eq. 19)"
    if method == "pso" and params.get("w") == 1.0:
        name = "PSO (printed eq. 10)"
    if params.get("selection") == "karaboga":
        name += ", fit = 1/(1+f)"
    return name


def spec_name(spec) -> str:
    return algorithm_name(spec.name, spec.params, spec.label)


def position_unit(mechanism) -> str:
    """The length unit of a serial arm's pose (mm for the DH arms, m for URDF/MJCF arms)."""
    return (getattr(mechanism, "pose_units", None) or ("mm",))[0]


def fitness_label(mechanism, objective: str | None) -> str:
    """Axis label of the fitness with its unit, from the mechanism's units and the objective
    (a serial arm: ΔP in its length unit plus ΔR in degrees, :class:`fkopt.problems.IKProblem`)."""
    if getattr(mechanism, "kind", "") == "serial":
        return f"objective f = ΔP + ΔR ({position_unit(mechanism)} + deg)"
    units = sorted(set(getattr(mechanism, "joint_units", ())))
    if objective == "absolute":
        return f"fitness Σ|Δl| ({' + '.join(units)})"
    return f"fitness Σ Δ² ({' + '.join(u + '²' for u in units)})"


def legend_off_data(ax, source=None, **kwargs) -> None:
    """The legend of ``source``'s curves (default: ``ax``'s) to the right of ``ax``, outside
    every axis, so it never covers data (``save``'s tight bounding box keeps it in the file)."""
    handles, labels = (source or ax).get_legend_handles_labels()
    if handles:
        ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, **kwargs)


def floor_of(*arrays) -> float:
    """A decade below the smallest positive value of ``arrays`` (at least MIN_FLOOR)."""
    pos = [np.min(a[a > 0]) for a in (np.asarray(x, float) for x in arrays) if np.any(a > 0)]
    if not pos:
        return 1e-16
    return max(MIN_FLOOR, 10.0 ** (np.floor(np.log10(min(pos))) - 1))


def mark_zero(ax, floor: float) -> None:
    """Grey band at ``floor`` on a log y axis: where exact zeros are drawn."""
    ax.axhspan(floor / 3, floor * 1.5, color="0.85", lw=0, zorder=0)
    ax.annotate("0 (exact, drawn at floor)", (0.99, floor), xycoords=("axes fraction", "data"),
                ha="right", va="bottom", fontsize=7, color="0.35")
    lo, hi = ax.get_ylim()
    ax.set_ylim(min(lo, floor / 3), hi)
