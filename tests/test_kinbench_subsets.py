"""Solver subsets of a suite (``subsets:``, kinbench v3's evaluations track in full): solvers that
run fewer cells, one-line errors for a bad subset, and boards that compare solvers only on the
cells (problem, set, pose, run) they all ran."""
import json

import pandas as pd
import pytest

from fkopt.errors import FkoptError
from fkopt.run.pipeline import load_any, run_config
from fkopt.kinbench import measures as M
from fkopt.kinbench.budget import target_column
from fkopt.kinbench.config import load_suite

from test_kinbench import SUITES, tiny

SOLVERS = [{"name": "lm"}, {"name": "pso"}, {"name": "gabc"}]
SWARMS = {"name": "swarms", "solvers": ["pso", "gabc"], "problems": ["mao2017-3rps"], "sets": ["uniform", "boundary"],
          "poses": 1, "runs": 1}


def subset_suite(tmp_path, **over):
    """lm on every cell (2 problems x 4 sets x 2 poses x 2 runs), pso and gabc on a subset of them."""
    return tiny(tmp_path, solvers=SOLVERS, subsets=[SWARMS], budget_per_dim=300, **over)


# -- config -------------------------------------------------------------------------------------
@pytest.mark.parametrize("subset, fragment", [
    ({**SWARMS, "solvers": ["nope"]}, "subsets[0].solvers: 'nope' is not one of the suite's solvers (allowed: lm, pso, gabc)"),
    ({**SWARMS, "problems": ["ur5"]}, "subsets[0].problems: 'ur5' is not one of the suite's problems (allowed: "
                                      "mao2017-3rps, wu2015-3ppr)"),
    ({**SWARMS, "poses": 3}, "subsets[0].poses: 3 (allowed: 1 to the suite's poses, 2)"),
    ({**SWARMS, "runs": 5}, "subsets[0].runs: 5 (allowed: 1 to the suite's runs, 2)"),
    ({**SWARMS, "name": "full"}, "subsets[0].name: 'full' is taken"),
    ({**SWARMS, "sets": ["sideways"]}, "subsets[0].sets[0]"),
    ({**SWARMS, "budget_per_dim": 10}, "budget_per_dim"),
])
def test_a_bad_subset_is_one_line_naming_the_file_the_field_and_what_is_allowed(tmp_path, subset, fragment):
    path = tiny(tmp_path, solvers=SOLVERS, subsets=[subset])
    with pytest.raises(FkoptError) as err:
        load_any(path)
    text = str(err.value)
    assert fragment in text and str(path) in text and "\n" not in text, text


def test_a_solver_in_two_subsets_and_a_set_the_suite_does_not_run_are_refused(tmp_path):
    two = json.loads(json.dumps([SWARMS, {**SWARMS, "name": "again"}]))     # no YAML aliases
    with pytest.raises(FkoptError, match=r"subsets\[1\]\.solvers: 'pso' is already in subset 'swarms'"):
        load_any(tiny(tmp_path, solvers=SOLVERS, subsets=two))
    with pytest.raises(FkoptError, match=r"subsets\[0\]\.sets: 'printed' is not one of the suite's sets"):
        load_any(tiny(tmp_path / "b", solvers=SOLVERS, sets=["uniform", "boundary"],
                      subsets=[{**SWARMS, "sets": ["printed"]}]))


def test_v3_runs_exact_and_lm_on_every_cell_and_the_others_on_their_subsets():
    cfg = load_suite(SUITES / "kinbench-v3.yaml")
    boards = dict(cfg.board_cells())
    assert set(boards["full"]) == {"exact", "lm"} and list(boards) == ["full", "local", "per-point", "de"]
    names = {p.name for p in cfg.problems}
    per_point = next(s for s in cfg.subsets if s.name == "per-point")
    assert {"ur5", "panda", "iiwa-mj", "dh-chain-3", "dh-chain-30"} <= set(per_point.problems) < names
    assert cfg.quick_tier().subsets == []          # the quick tier is itself small: all its solvers on all its cells
    assert "subsets" not in load_suite(SUITES / "kinbench-v2.yaml").stored_dump()   # v1/v2's meta.json unchanged


# -- boards ---------------------------------------------------------------------------------------
def _runs(rows):
    """A run record of (problem, pose, solver, evaluations to 1e-2 or None) rows, one set, run 0."""
    df = pd.DataFrame(rows, columns=["problem", "pose", "solver", "hit"])
    return df.assign(set="uniform", run=0, dim=1, track="black-box", **{"class": "c"},
                     evaluations=df["hit"].fillna(100).astype(float), fitness=1.0,
                     **{target_column(1e-2): df["hit"].astype(float)}).drop(columns="hit")


def test_a_board_holds_only_the_cells_all_its_solvers_ran():
    # "full" solves poses 0-3 of p at 10 evaluations on 0 and 1 and never on 2 and 3; "sub" ran
    # only poses 0 and 1 (its subset), at 50. Counting full's misses on poses 2 and 3 against it
    # would rank sub first; on the cells both ran, full is better.
    rows = [("p", k, "full", 10 if k < 2 else None) for k in range(4)] + [("p", k, "sub", 50) for k in range(2)]
    runs = _runs(rows)
    (n_full, full), (n_sub, sub) = M.boards(runs, [("full", ["full"]), ("sub", ["sub"])])
    assert set(full["solver"]) == {"full"}            # sub is missing poses 2, 3: not on the full board
    assert set(sub["solver"]) == {"full", "sub"} and set(sub["pose"]) == {0, 1}
    lb = M.leaderboard_table(sub, [1e-2], 100, bootstrap=100)
    board = lb[lb.scope == "overall"].set_index("solver")
    assert board.loc["full", "score"] > board.loc["sub", "score"] and board.loc["full", "success_1e-02"] == 1.0
    assert (board["instances"] == 2).all()
    wrong = M.leaderboard_table(runs, [1e-2], 100, bootstrap=100)     # what every cell of full would say
    assert wrong.set_index(["scope", "solver"]).loc[("overall", "full"), "success_1e-02"] == 0.5
    ert = M.ert_ratio_table(sub, [1e-2]).set_index("solver")
    assert ert.loc["full", "ert_ratio"] == 1.0 and ert.loc["sub", "ert_ratio"] == 5.0


def test_a_solver_missing_one_cell_is_not_on_the_board():
    rows = [("p", k, "a", 10) for k in range(3)] + [("p", k, "b", 10) for k in (0, 2)]
    (_, board), = M.boards(_runs(rows), [("a", ["a"])])
    assert set(board["solver"]) == {"a"}


# -- end to end: the one suite pipeline -------------------------------------------------------------
@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """The subset suite run once in this process: (suite file, results root, its folder, result)."""
    tmp = tmp_path_factory.mktemp("subsets")
    path = subset_suite(tmp)
    ran = run_config(load_any(path), tmp / "out", source=str(path))
    return path, tmp / "out", ran.folder, ran.result


def test_a_subset_suite_writes_one_board_per_subset(written):
    _, _, folder, _ = written
    runs = pd.read_csv(folder / "runs.csv")
    assert (runs.solver == "lm").sum() == 2 * 4 * 2 * 2 and (runs.solver == "pso").sum() == 1 * 2 * 1 * 1
    lb = pd.read_csv(folder / "leaderboard.csv")
    assert set(lb.loc[lb.scope == "board:full/overall", "solver"]) == {"lm"}
    sub = lb[lb.scope == "board:swarms/overall"].set_index("solver")
    assert set(sub.index) == {"lm", "pso", "gabc"} and (sub["instances"] == 2).all()    # the 2 cells pso ran
    ms = pd.read_csv(folder / "measures.csv")
    assert set(ms.loc[(ms.board == "swarms"), "trials"]) == {1}                 # lm: run 0 of those cells only
    ecdf = pd.read_csv(folder / "ecdf.csv")
    assert {"board:full/all", "board:swarms/all", "board:swarms/class:parallel-fk-3dof"} <= set(ecdf.scope)
    er = pd.read_csv(folder / "ert_ratio.csv")
    assert set(er.board) == {"full", "swarms"} and (er.loc[er.board == "full", "solver"] == "lm").all()
    assert (folder / "ecdf_swarms_all.png").exists() and (folder / "ecdf_full_all.png").exists()
    md = (folder / "leaderboard.md").read_text()
    assert "### board:swarms/track:black-box" in md and "### board:swarms/class:parallel-fk-3dof/track:black-box" \
        in md.split("## ERT ratio to the virtual best solver")[1]      # pso beside gabc; lm alone in its track: none
    assert "Boards: each compares only the solvers that ran every cell" in md
    page = (folder / "index.html").read_text()
    assert "Boards: each compares" in page and 'src="ecdf_full_all.png"' in page
    assert "Ranking board:swarms/overall" in (folder / "rankings.html").read_text()
    assert json.loads((folder / "meta.json").read_text())["config"]["subsets"][0]["name"] == "swarms"


def test_fkopt_check_reruns_a_subset_suite_and_finds_an_edited_number(written, tmp_path):
    import shutil
    from fkopt.reproduce.check import check_experiment
    from fkopt.reproduce.store import Store
    _, root, folder, _ = written
    assert check_experiment(Store(root).get("kinbench", "tiny")) == []
    copy = tmp_path / "kinbench" / "tiny"
    shutil.copytree(folder, copy)
    er = pd.read_csv(copy / "ert_ratio.csv")
    er.loc[0, "ert"] *= 2                       # a stored number the rerun does not give
    er.to_csv(copy / "ert_ratio.csv", index=False)
    assert any(m.file == "ert_ratio.csv" for m in check_experiment(Store(tmp_path).get("kinbench", "tiny")))


def test_an_interrupted_subset_suite_resumes_with_the_same_bytes(written, tmp_path):
    path, _, whole, _ = written

    class Stop(KeyboardInterrupt):
        pass

    def stop_after_one(label, done, total):
        if done == 1:
            raise Stop
    out = tmp_path / "out"
    with pytest.raises(Stop):
        run_config(load_any(path), out, source=str(path), progress=stop_after_one)
    from fkopt.kinbench.kind import work_folder
    assert len(list((work_folder(out, load_any(path)) / "tasks").glob("p*-s*.json"))) == 1
    seen = []
    folder = run_config(load_any(path), out, source=str(path), resume=True,
                        progress=lambda label, done, total: seen.append((done, total))).folder
    assert seen == [(1, 4), (2, 4), (3, 4), (4, 4)]   # lm on two problems, pso and gabc on one: one kept
    for name in ("runs.csv", "measures.csv", "ecdf.csv", "leaderboard.csv", "ert_ratio.csv", "trace.csv.gz"):
        assert (folder / name).read_bytes() == (whole / name).read_bytes(), name


def test_a_subset_solver_gets_the_numbers_it_gets_on_the_whole_suite(written, tmp_path):
    """A subset cuts cells, it does not change them: pso's rows on its cells are those of pso run
    on every cell (seeds per case and run, not per task)."""
    from fkopt.kinbench.runner import run_suite
    cut = written[3].record
    every = run_suite(load_any(tiny(tmp_path, solvers=[{"name": "pso"}], budget_per_dim=300))).record
    key = ["problem", "set", "pose", "run"]
    a = cut[cut.solver == "pso"].reset_index(drop=True)
    b = every.merge(a[key], on=key).reset_index(drop=True)
    assert len(a) == 2 and len(every) == 2 * 4 * 2 * 2
    pd.testing.assert_frame_equal(a, b[a.columns])


def test_the_virtual_best_solves_a_cell_when_any_solver_does_at_the_fewest_evaluations():
    runs = _runs([("p", 0, "a", 10), ("p", 1, "a", None), ("p", 0, "b", 40), ("p", 1, "b", 20)])
    vbs = M.virtual_best_ecdf(runs, [1e-2])
    assert vbs["evals_per_dim"].tolist() == [10.0, 20.0] and vbs["fraction"].tolist() == [0.5, 1.0]
