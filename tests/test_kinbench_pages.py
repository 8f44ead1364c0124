"""kinbench's pages a roboticist reads in a minute (issue 37): index.html opens with which solver
per arm family and the summary per solver beside a figure, under a table of contents; per-arm
tables and every ranking on pages of their own, each under 500 kB; headers in words with units;
every entry's settings and the machine's load on the page; all of it made again from a stored
folder without running a solver (`fkopt pages`). And the ECDF figures' end-of-line names clear
of title and legend (a newcomer's finding, issue 41)."""
import hashlib
from html import unescape
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fkopt.kinbench import html as H
from fkopt.kinbench.pages import PAGE_LIMIT, stored_suite, write_pages

ROOT = Path(__file__).resolve().parent.parent
QUICK = ROOT / "results" / "kinbench" / "kinbench-v3-robots-quick"


# -- headers -------------------------------------------------------------------------------------
@pytest.mark.parametrize("column, header", [
    ("success_1e-05m_1e-05rad", "success at 1e-5 m and 1e-5 rad (%)"),
    ("success_5mm_0.05rad", "success at 5 mm and 0.05 rad (%)"),
    ("success_1e-06", "success at fitness 1e-6 (%)"),
    ("success_1e+00", "success at fitness 1 (%)"),
    ("time_ms_median", "median time to an answer (ms)"),
    ("cpu_ms_median", "median CPU time per call (ms)"),
    ("ert_ratio_1e-08", "ERT ratio to the virtual best at fitness 1e-8"),
    ("queue_wait_ms", "queue wait (ms)"),              # a column a newer board adds: its name, unit apart
])
def test_headers_are_words_with_units(column, header):
    assert H.words(column) == header


def test_a_table_keeps_the_csv_name_in_the_tooltip_and_shows_shares_in_per_cent():
    df = pd.DataFrame({"solver": ["a"], "success_1e-05m_1e-05rad": [0.975], "time_ms_median": [0.1901]})
    text = H.table_html(df, list(df.columns), "t")
    assert 'title="success_1e-05m_1e-05rad">success at 1e-5 m and 1e-5 rad (%)</th>' in re.sub(r"</?span[^>]*>", "", text)
    assert ">97.5<" in text and ">0.1901<" in text


def test_a_share_column_read_back_as_whole_numbers_is_shown_in_per_cent():
    """A stored CSV whose success column holds only 0 and 1 reads back as integers: `fkopt pages`
    showed them as 1 and 0 where the page made at the run showed 100 and 0."""
    df = pd.DataFrame({"solver": ["a", "b"], "success_1e-02": np.array([1, 0], dtype=np.int64), "runs": [3, 4]})
    text = H.table_html(df, list(df.columns), "t")
    assert "<td>100</td><td>3</td>" in text and "<td>0</td><td>4</td>" in text


# -- figures -------------------------------------------------------------------------------------
def test_end_labels_stay_inside_the_axes_and_apart():
    from fkopt.kinbench.reports import spread_labels
    ys = spread_labels([1.0, 1.0, 1.0, 0.99, 0.0], 0.05, 0.0, 1.0)
    assert max(ys) <= 1.0 and min(ys) >= 0.0
    assert np.diff(sorted(ys)).min() >= 0.05 - 1e-12
    many = spread_labels([1.0] * 30, 0.05, 0.0, 1.0)      # more names than fit: evenly over the height
    assert max(many) <= 1.0 and min(many) >= 0.0 and np.diff(sorted(many)).min() > 0


def _overlap(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


@pytest.fixture
def drawn(monkeypatch):
    """The figures a maker saves, measured before they are written: every end-of-line name's
    box against the title's and the legend's, and the title's width against the figure's."""
    import importlib
    plotting = importlib.import_module("fkopt.run.plotting")
    seen = []
    original = plotting.save

    def save(fig, path, vector=True):
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        for ax in fig.axes:
            names = [t.get_window_extent(renderer) for t in ax.texts]
            title = ax.title.get_window_extent(renderer)
            legend = ax.get_legend().get_window_extent(renderer) if ax.get_legend() else None
            seen.append({"path": Path(path).name, "names": names, "title": title, "legend": legend,
                         "figure_width": fig.bbox.width})
        return original(fig, path, vector=False)
    monkeypatch.setattr(plotting, "save", save)
    return seen


def _clear(fig):
    assert fig["title"].width <= fig["figure_width"], fig["path"]          # the title fits the figure
    for box in fig["names"]:
        assert not _overlap(box, fig["title"]), fig["path"]
        assert fig["legend"] is None or not _overlap(box, fig["legend"]), fig["path"]


def test_ecdf_end_labels_clear_the_title_and_the_legend(tmp_path, drawn):
    from types import SimpleNamespace
    from fkopt.kinbench.reports import ecdf_figures
    solvers = [("exact", "exact"), ("lm", "jacobian"), ("dls", "jacobian"), ("pso", "black-box"), ("abc", "black-box")]
    rows = [{"scope": "board:full/all", "solver": s, "track": t, "evals_per_dim": e, "reached": 1, "pairs": 1,
             "fraction": f} for s, t in solvers for e, f in ((2.0, 0.5), (50.0, 1.0))]
    targets = [1.0, 0.1, 0.01, 1e-4, 1e-6, 1e-8, 1e-10]
    sr = SimpleNamespace(config=SimpleNamespace(targets=targets, budget_per_dim=2000, name="kinbench-v3", subsets=[]),
                         record=pd.DataFrame({"class": []}))
    ecdf_figures(sr, tmp_path, {"ecdf.csv": pd.DataFrame(rows)})
    assert drawn and all(len(f["names"]) == len(solvers) for f in drawn)
    for fig in drawn:
        _clear(fig)


def test_clock_end_labels_clear_the_title(tmp_path, drawn):
    from fkopt.kinbench.reports import clock_figures
    sr, tables = stored_suite(QUICK)
    answers = tables["answers.csv.gz"]
    names = clock_figures(sr, tmp_path, {"answers.csv.gz": answers[answers["problem"].isin(["ur5", "panda"])]})
    assert "clock_all.png" in names and "clock_ur5.png" in names
    for fig in drawn:
        _clear(fig)


# -- pages ---------------------------------------------------------------------------------------
def _newer_board(tables):
    """The stored quick board as the next board version might be: a new outside solver and new
    columns (cpu_ms_median and one this code has never heard of)."""
    board = tables["leaderboard-robots.csv"].copy()
    answers = tables["answers.csv.gz"]
    # a stored board of version 2 has eaik already: the stand-in replaces its rows by tracik's
    board = pd.concat([board[board["solver"] != "eaik"], board[board["solver"] == "tracik"].assign(solver="eaik")],
                      ignore_index=True)
    board["cpu_ms_median"] = board["time_ms_median"] * 0.5
    board["queue_wait_ms"] = 0.0
    answers = pd.concat([answers[answers["solver"] != "eaik"], answers[answers["solver"] == "tracik"].assign(solver="eaik")],
                        ignore_index=True)
    return {**tables, "leaderboard-robots.csv": board, "answers.csv.gz": answers}


def _anchors(text):
    return set(re.findall(r'id="([^"]+)"', text))


def _toc_targets(text):
    nav = re.search(r'<nav class="toc" id="toc">(.*?)</nav>', text, re.S).group(1)
    return re.findall(r'href="#([^"]+)"', nav)


def test_the_board_page_opens_with_the_advice_and_takes_new_solvers_and_columns(tmp_path):
    sr, tables = stored_suite(QUICK)
    folder = tmp_path / "board"
    folder.mkdir()
    names = write_pages(sr, folder, _newer_board(tables))
    index = (folder / "index.html").read_text()
    assert names[0] == "index.html" and "arms.html" in names and "rankings.html" in names
    for name in names:
        assert (folder / name).stat().st_size < PAGE_LIMIT, name
        text = (folder / name).read_text()
        targets = _toc_targets(text)
        assert targets and set(targets) <= _anchors(text), name            # every contents link lands
        ids = re.findall(r'id="([^"]+)"', text)
        assert len(ids) == len(set(ids)), name                              # each lands on one place
    order = [index.index(f'id="{i}"') for i in ("toc", "advice", "summary", "figures", "settings", "machine")]
    assert order == sorted(order)
    summary = index[index.index('id="summary"'):index.index('id="figures"')]
    assert ">eaik<" in summary and "median CPU time per call (ms)" in summary
    assert "success at 1e-5 m and 1e-5 rad (%)" in re.sub(r"</?span[^>]*>", "", index)
    assert "success_1e-05m_1e-05rad" in index
    arms = (folder / "arms.html").read_text()
    assert "queue wait (ms)" in arms and ">eaik<" in arms and 'href="index.html"' in arms
    settings = index[index.index('id="settings"'):index.index('id="machine"')]
    for solver in set(tables["answers.csv.gz"]["solver"]) | {"eaik"}:
        assert f">{solver}<" in settings, solver
    assert "eps = 1e-5" in settings                 # TRAC-IK's, as its wrapper documents it
    if sr.meta.get("load_avg"):                     # board version 2 records the machine's load
        from fkopt.kinbench.pages import load_text
        assert load_text(sr.meta) in unescape(index) and "not recorded (this board" not in unescape(index)
    else:
        assert "not recorded (this board was stored before kinbench recorded the machine's load)" in unescape(index)
    assert "data:image" not in index and "http://" not in index and "https://" not in index


def test_an_arm_a_package_cannot_take_is_left_out_not_counted_as_zero(tmp_path):
    from fkopt.kinbench.advice import summarise_board
    sr, tables = stored_suite(QUICK)
    tables = _newer_board(tables)
    board = tables["leaderboard-robots.csv"]
    success = [c for c in board.columns if c.startswith("success_")]
    board[success] = board[success].astype(object)
    board.loc[(board["solver"] == "eaik") & (board["robot"] == "panda"), success] = "not applicable: no decomposition"
    summary = summarise_board(board, 20.0).set_index("solver")
    ik_arms = board.loc[board["other_mode"].isna(), "robot"].nunique()
    assert summary.loc["eaik", "arms"] == ik_arms - 1 and summary.loc["tracik", "arms"] == ik_arms
    rung = "success_1e-05m_1e-05rad"              # eaik's rows are tracik's: its mean is tracik's without panda
    others = board[(board["solver"] == "tracik") & (board["timeout_ms"] == 20.0) & board["other_mode"].isna()
                   & (board["robot"] != "panda")]
    assert summary.loc["eaik", rung] == pytest.approx(100 * others[rung].astype(float).mean())
    write_pages(sr, tmp_path, {**tables, "leaderboard-robots.csv": board})
    assert "not applicable: no decomposition" in (tmp_path / "arms.html").read_text()


def _settings_rows(index: str) -> dict:
    """solver -> the cells of its row in the page's settings table."""
    table = re.search(r'<table class="sortable" id="settings-table">(.*?)</table>', index, re.S).group(1)
    rows = {}
    for tr in re.findall(r"<tr>(.*?)</tr>", table, re.S)[1:]:
        cells = [unescape(re.sub(r"<[^>]+>", "", c)) for c in re.findall(r"<td[^>]*>(.*?)</td>", tr, re.S)]
        rows[cells[0]] = cells
    return rows


def test_the_page_shows_the_load_and_settings_a_board_recorded(tmp_path):
    """meta.json's ``entries`` (what the runner writes) is what the page shows as the settings the
    board ran with; an entry meta.json does not name says it was not recorded."""
    sr, tables = stored_suite(QUICK)
    entries = {k: v for k, v in sr.meta["entries"].items() if k != "pin-clik"}
    sr.meta = {**sr.meta, "load_avg": {"start": [1.25, 0.5, 0.25], "end": [2.0, 1.0, 0.5]},
               "entries": {**entries, "tracik": {"eps": 5.77e-06, "solve_type": "Speed"}}}
    write_pages(sr, tmp_path, tables)
    index = (tmp_path / "index.html").read_text()
    assert "at its start: 1.25 / 0.50 / 0.25; at its end: 2.00 / 1.00 / 0.50" in index
    rows = _settings_rows(index)
    assert rows["tracik"][4] == "eps = 5.77e-06; solve_type = Speed"
    assert rows["pin-clik"][4] == "not recorded with this board"
    assert rows["pin-clik"][5].startswith("Settings: dt = 1")          # as its wrapper documents it


def test_the_stored_board_page_shows_every_entrys_recorded_settings_and_the_throughput_track(tmp_path):
    """The stored quick board (version 2, meta.json ``entries``): every entry it recorded shows
    those settings, each beside its wrapper's documented ones; pytorch-kinematics, on the
    throughput track only, has its row there and its rates in the throughput table."""
    from fkopt.kinbench.advice import summarise_throughput
    sr, tables = stored_suite(QUICK)
    write_pages(sr, tmp_path, tables)
    index = (tmp_path / "index.html").read_text()
    rows = _settings_rows(index)
    for name, settings in sr.meta["entries"].items():
        settings = dict(settings)
        package = settings.pop("package", None)          # its own column, with the version the board ran
        if package is not None:
            assert rows[name][2] == package, name
        assert rows[name][4] == "; ".join(f"{k} = {v}" for k, v in settings.items()), name
        assert rows[name][5] not in ("", "-"), name
    assert rows["tracik"][2].startswith("pytracik ")            # the board recorded the packages' versions
    assert "One outside IK solver" not in rows["ikpy"][5] and "symbolic=True" in rows["ikpy"][5]
    assert rows["optik"][5].rstrip().endswith("deterministic results.")     # the list after "except:"
    assert rows["pytorch-kinematics"][3].startswith("throughput track only")
    assert "PseudoInverseIK" in rows["pytorch-kinematics"][5]
    assert 'href="#throughput"' in index and 'id="throughput-table"' in index
    assert "Outside entries: each as its authors run it" in unescape(index)     # where the reproductions are
    rates = summarise_throughput(tables["throughput.csv"])
    torch = rates[rates["solver"] == "pytorch-kinematics"]
    assert not torch.empty and (torch["arms"] == tables["throughput.csv"].query(
        "solver == 'pytorch-kinematics'")["robot"].nunique()).all()


def test_the_throughput_summary_is_the_medians_and_means_over_the_arms():
    from fkopt.kinbench.advice import summarise_throughput
    tp = pd.DataFrame({"solver": ["a", "a", "a", "b"], "robot": ["r1", "r2", "r3", "r1"], "entry": ["outside"] * 4,
                       "batch": [10, 10, 10, 10], "queries_per_s": [100.0, 300.0, 200.0, 50.0],
                       "reference": ["ref"] * 4, "reference_queries_per_s": [10.0, 20.0, 30.0, 10.0],
                       "ratio": [10.0, 15.0, 6.0, 5.0], "success_1e-05m_1e-05rad": [1.0, 0.5, 0.0, 1.0]})
    out = summarise_throughput(tp).set_index("solver")
    assert out.loc["a", "arms"] == 3 and out.loc["a", "queries_per_s"] == 200.0
    assert out.loc["a", "ratio"] == 10.0 and out.loc["a", "reference_queries_per_s"] == 20.0
    assert out.loc["a", "success_1e-05m_1e-05rad"] == pytest.approx(50.0)
    assert out.loc["b", "arms"] == 1 and out.loc["b", "success_1e-05m_1e-05rad"] == 100.0


def test_the_advice_per_family_is_the_summary_of_its_arms():
    """The opening table's row of a family is robots_summary's first row over that family's arms."""
    from fkopt.kinbench.advice import family_advice, summarise_board
    board = pd.read_csv(QUICK / "leaderboard-robots.csv")
    sr, _ = stored_suite(QUICK)
    families = {p.name: p.problem_class for p in sr.config.problems}
    advice = family_advice(board, families)
    assert set(advice["family"]) == {families[r] for r in board["robot"]}
    for row in advice.itertuples():
        arms = row.arms.split(", ")
        best = summarise_board(board[board["robot"].isin(arms)], row.timeout_ms, fk=row.family.startswith("parallel"))
        best = best[best["not_applicable"] == 0]          # an entry that cannot take one of the arms is no advice
        assert best.iloc[0]["solver"] == row.solver


def test_the_advice_per_family_never_names_an_entry_that_cannot_take_one_of_its_arms():
    """OptIK is "not applicable" on the TIAGo with its torso lift (8-10 joints) and would lead that family
    on success then ratio; the family's advice is the best entry that takes every one of its arms."""
    from fkopt.kinbench.advice import family_advice, summarise_board
    board = pd.read_csv(ROOT / "results" / "kinbench" / "kinbench-v3-robots" / "leaderboard-robots.csv")
    sr, _ = stored_suite(QUICK)
    families = {p.name: p.problem_class for p in sr.config.problems}
    family = [r for r, f in families.items() if f == "serial-ik-8to10dof" and r in set(board["robot"])]
    assert "tiago-torso" in family
    sub = board[board["robot"].isin(family)]
    ranked = summarise_board(sub, 20.0)
    leader = ranked.iloc[0]
    advice = family_advice(sub, families).set_index("family").loc["serial-ik-8to10dof"]
    if leader["not_applicable"] > 0:                  # the stored board: OptIK first on the arms it takes
        assert advice["solver"] != leader["solver"]
        # ... and named beside the advice with the arms it takes, not hidden
        assert advice["leads_where_it_applies"].startswith(f"{leader['solver']}: ")
        assert f"on {int(leader['arms'])} of {len(family)} arms" in advice["leads_where_it_applies"]
    else:
        assert advice["leads_where_it_applies"] == ""
    assert advice["not_applicable"] == 0
    assert advice["solver"] == ranked[ranked["not_applicable"] == 0].iloc[0]["solver"]


def test_fkopt_pages_refuses_what_is_not_a_suite_in_one_line(tmp_path, fkopt_run):
    (tmp_path / "exp").mkdir()
    (tmp_path / "exp" / "meta.json").write_text(json.dumps({"kind": "experiment"}))
    for target, fragment in ((tmp_path / "exp", "kind: 'experiment' (allowed: suite"),
                             (tmp_path / "none", "no such folder")):
        proc = fkopt_run("pages", str(target))
        assert proc.returncode == 2 and fragment in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
        assert "Traceback" not in proc.stderr


def _digests(folder):
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in folder.iterdir()
            if p.name.endswith((".csv", ".csv.gz")) or p.name in ("meta.json", "env.json")}


def test_fkopt_pages_remakes_a_stored_board_from_its_files_alone(tmp_path):
    """From a copy of the stored quick board: figures and pages written again, no table touched
    (no solver runs: the stored answers are all there is)."""
    folder = tmp_path / "kinbench-v3-robots-quick"
    shutil.copytree(QUICK, folder)
    before = _digests(folder)
    for name in [p.name for p in folder.glob("*.png")] + ["index.html"]:
        (folder / name).unlink()
    proc = subprocess.run([sys.executable, "-m", "fkopt.cli", "pages", str(folder)], capture_output=True, text=True,
                          env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    assert proc.returncode == 0, proc.stderr
    assert _digests(folder) == before
    assert {"index.html", "arms.html", "rankings.html", "clock_all.png", "clock_ur5.png", "ecdf_all.png"} <= \
        {p.name for p in folder.iterdir()}
    index = (folder / "index.html").read_text()
    assert all((folder / src).is_file() for src in re.findall(r'<img [^>]*src="([^"]+)"', index))
