"""Figures read without guessing (issue 23): the convergence figure draws the threshold, the
variables figure keeps its legend off the curves and spreads the early iterations, and the two
y-axes of scaling.png differ by more than colour."""
from pathlib import Path

import numpy as np
import pytest

from fkopt.tools.bench import scaling
from fkopt.kinds.experiment import reports
from fkopt.kinds.experiment.config import ExperimentConfig
from fkopt.kinds.experiment.runner import run_experiment


@pytest.fixture
def drawn(monkeypatch, tmp_path):
    """Run a small experiment with the variables figure; return {file stem: matplotlib figure}."""
    figures = {}

    def keep(fig, path):
        figures[Path(path).stem] = fig
        return []
    monkeypatch.setattr(reports, "_save", keep)
    config = ExperimentConfig(name="figs", mechanism={"name": "3-rps"},
                              cases=[{"pose": {"alpha": 9, "beta": 13, "z": 622}}],
                              algorithms=[{"name": "gabc"}, {"name": "pso"}], population=6, iterations=40,
                              runs=3, threshold=1e-4, figures=["variables"])
    er = run_experiment(config, timing=False)
    reports.convergence_figure(er, tmp_path, {})
    reports.variables_figure(er, tmp_path, {})
    return figures


def test_convergence_draws_the_threshold(drawn):
    fig = drawn["convergence"]
    for ax in fig.axes[:2]:
        flat = [line for line in ax.get_lines() if np.allclose(line.get_ydata(), 1e-4)]
        assert flat, "no horizontal line at the threshold"
    assert any("threshold" in t.get_text() for t in fig.axes[1].get_legend().get_texts())


def test_variables_legend_outside_the_panels_and_log_iterations(drawn):
    fig = drawn["variables"]
    panels = [ax for ax in fig.axes if ax.get_visible()]
    assert all(ax.get_legend() is None for ax in panels)          # no legend inside a panel
    assert len(fig.legends) == 1
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    renderer = FigureCanvasAgg(fig).get_renderer()
    legend_box = fig.legends[0].get_window_extent(renderer)
    for ax in panels:
        assert ax.get_xscale() == "symlog"
        assert not legend_box.overlaps(ax.get_tightbbox(renderer))     # panel with its labels
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert len(labels) == 3 and labels[-1] == "true value"


def test_scaling_axes_differ_by_marker_style_label_and_title(tmp_path):
    curves = {"population": [(10, 0.5, 2000.0), (100, 1.0, 900.0), (1000, 3.0, 600.0)],
              "runs": [(1, 0.1, 20000.0), (100, 0.4, 900.0), (1000, 2.0, 500.0)]}
    fig = scaling.plot_scaling(curves, tmp_path / "scaling.png", 50)
    assert (tmp_path / "scaling.png").is_file()
    left = [ax for ax in fig.axes if ax.get_title()]
    assert len(left) == 2 and left[0].get_title() != left[1].get_title()
    for ax in left:
        twin = next(a for a in fig.axes if a is not ax and a.bbox.bounds == ax.bbox.bounds)
        mine, theirs = ax.get_lines()[0], twin.get_lines()[0]
        assert mine.get_marker() != theirs.get_marker() and mine.get_linestyle() != theirs.get_linestyle()
        assert ax.get_ylabel() != twin.get_ylabel()
        assert len(ax.get_legend().get_texts()) == 2


def test_serial_fitness_label_takes_the_arms_length_unit_and_legends_stay_off_the_axes():
    """Issue 32: the Panda's convergence figure said (mm + deg) for an arm in metres, and its
    legend covered the curves."""
    import numpy as np

    import fkopt
    from fkopt.run import plotting
    urdf = fkopt.mechanism("urdf", file="configs/suites/robots/ur5.urdf", base="base_link", tip="tool0")
    assert plotting.fitness_label(urdf, None).endswith("(m + deg)")
    assert plotting.fitness_label(fkopt.mechanism("7dof-arm"), "paper").endswith("(mm + deg)")
    plt = plotting.plt()
    fig, axes = plt.subplots(1, 2)
    for k in range(4):
        axes[0].plot(np.arange(10), np.arange(10) * (k + 1), label=f"curve {k}")
    plotting.legend_off_data(axes[-1], source=axes[0])
    fig.canvas.draw()
    box = axes[-1].get_legend().get_window_extent()
    assert all(not box.overlaps(ax.get_window_extent()) for ax in axes)
    plt.close(fig)
