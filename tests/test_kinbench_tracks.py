"""kinbench's all-solutions and paths tracks (fkopt/kinbench/solution_sets.py, paths.py,
branch_tracks.py): the frozen path set, the verdicts, the boards, and fkopt check's
re-verification of the stored answers."""
from __future__ import annotations

import gzip
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fkopt.errors import FkoptError
from fkopt.kinbench import paths as path_track
from fkopt.kinbench import solution_sets
from fkopt.kinbench.branch_tracks import reverify
from fkopt.kinbench.config import load_suite, suite_from_dict
from fkopt.kinbench.releases import RELEASES
from fkopt.registry import ALL_SOLUTIONS_SOLVERS, PATH_SOLVERS, SOLVERS

ROOT = Path(__file__).resolve().parents[1]
SUITE = ROOT / "configs" / "suites" / "kinbench-v3-solutions.yaml"
STORED = ROOT / "results" / "kinbench" / "kinbench-v3-solutions-quick"


@pytest.fixture(scope="module")
def config():
    return load_suite(SUITE)


@pytest.fixture(scope="module")
def ur5(config):
    return solution_sets.track_arms(config, "ur5")[0]


def test_the_entries_are_in_the_one_registry_with_their_track():
    assert ALL_SOLUTIONS_SOLVERS == ("fkopt.inverse-all", "eaik-all", "rtb-ik_LM-restarts", "tracik-restarts")
    assert PATH_SOLVERS == ("fkopt.inverse_path", "rtb-ik_LM-seeded", "tracik-seeded")
    assert {SOLVERS[n].track for n in ALL_SOLUTIONS_SOLVERS} == {"all-solutions"}
    assert {SOLVERS[n].track for n in PATH_SOLVERS} == {"paths"}


def test_the_suite_names_its_tracks_as_read_and_its_quick_tier_cuts_them(config):
    dumped = config.stored_dump()
    assert {"all-solutions", "paths"} <= set(dumped["tracks"]) and "all_solutions" not in dumped["tracks"]
    assert suite_from_dict(dumped, "x").stored_dump() == dumped
    q = config.quick_tier()
    assert q.tracks.all_solutions.problems == ["ur5", "z1", "panda"] and q.tracks.all_solutions.queries == 5
    assert q.tracks.all_solutions.locked == {"panda": "panda_joint7"}
    assert q.tracks.paths.problems == ["ur5", "z1", "panda"] and q.tracks.paths.paths == 2


@pytest.mark.parametrize("edit, words", [
    (lambda t: t["all-solutions"].update(solvers=["fkopt.inverse-all", "tracik"]), "not an entry of the all-solutions"),
    (lambda t: t["paths"].update(reference="eaik-all"), "reference: 'eaik-all' is not one of the track's solvers"),
    (lambda t: t["paths"].update(problems=["ur5", "nope"]), "'nope' is not one of the suite's problems"),
    (lambda t: t["all-solutions"].update(locked={"nope": "j"}), "locked: 'nope'"),
])
def test_a_bad_track_field_is_one_line(config, edit, words):
    data = config.stored_dump()
    edit(data["tracks"])
    with pytest.raises(FkoptError) as err:
        suite_from_dict(data, "suite.yaml")
    assert words in str(err.value) and "\n" not in str(err.value)


def test_the_path_set_is_frozen_released_and_regenerates_bit_for_bit(config):
    sets = path_track.load_path_sets(config)
    assert set(sets) == set(config.tracks.paths.problems)
    release = RELEASES["kinbench-v3-paths"].files
    assert sorted(release) == sorted(f"kinbench-v3-paths/{p.name}" for p in (SUITE.parent / "kinbench-v3-paths").iterdir())
    for name, ends in sets.items():
        arm = next(p for p in [solution_sets.track_arms(config, n)[0] for n in [name]])
        again = path_track.generate(arm, name, config.seed, 20)[:len(ends)]
        assert np.array_equal(again, ends)
        Q = path_track.waypoints(ends)
        assert Q.shape == (len(ends), path_track.WAYPOINTS, arm.dof)
        step = np.abs(np.diff(np.radians(Q), axis=1)).max()
        assert step <= path_track.STEP + 1e-12                 # a branch with steps <= 0.05 rad exists
        assert arm.in_bounds(Q.reshape(-1, arm.dof)).all()


def test_an_edited_path_set_is_refused_with_one_line(config, tmp_path):
    folder = tmp_path / "suites"
    shutil.copytree(SUITE.parent / "kinbench-v3-paths", folder / "kinbench-v3-paths")
    f = folder / "kinbench-v3-paths" / "ur5.csv"
    f.write_text(f.read_text().replace("1", "2", 1))
    with pytest.raises(FkoptError, match="ur5.csv") as err:
        path_track.load_path_sets(config, folder)
    assert "\n" not in str(err.value)


def test_a_path_fails_on_a_flip_or_a_wrong_waypoint_and_passes_on_its_branch(config, ur5):
    ends = path_track.load_path_sets(config)["ur5"][:1]
    Q = path_track.waypoints(ends)[0]
    good = path_track.path_rows(ur5, "ur5", "x", 0, Q, Q, 1.0, 1.0, 1.0)
    assert path_track.path_success(good)
    flipped = Q.copy()
    flipped[50:, 0] += 360.0 * 0 + 10.0            # a 10 deg jump: the tip moves too, and the step is over the bound
    assert not path_track.path_success(path_track.path_rows(ur5, "ur5", "x", 0, flipped, Q, 1.0, 1.0, 1.0))
    wrapped = Q.copy()
    wrapped[:, 0] += 0.5                            # every waypoint 0.5 deg off: steps fine, tip wrong
    rows = path_track.path_rows(ur5, "ur5", "x", 0, wrapped, Q, 1.0, 1.0, 1.0)
    assert not path_track.path_success(rows) and (rows["step_rad"].iloc[1:] <= path_track.BOUND).all()
    board = path_track.paths_board(pd.concat([good.assign(solver="a"), rows.assign(solver="b")]), reference="a")
    assert board.set_index("solver")["success"].to_dict() == {"a": 1.0, "b": 0.0}


def test_distinct_answers_are_merged_modulo_2pi_after_mapping_into_the_limits(config, ur5):
    q = np.array([30.0, -60.0, 80.0, -40.0, 70.0, 20.0])
    assert np.allclose(solution_sets.into_limits(ur5, q[None] + [720.0, 0, 0, 0, 0, -1080.0]), [q - [0, 0, 0, 0, 0, 360.0]])   # UR5: +-360 deg, fewest turns
    reps, copies = solution_sets.distinct(ur5, np.stack([q, q + [360.0, 0, 0, 0, 0, 0], q + [0, 0, 0, 0, 0, 1.0]]))
    assert len(reps) == 2 and copies.tolist() == [2, 1]


def test_recall_counts_distinct_verified_answers_against_the_analytic_set_and_the_union(ur5):
    import fkopt
    T = ur5.fk_matrix(np.array([[30.0, -60.0, 80.0, -40.0, 70.0, 20.0]]))[0]
    q, other = fkopt.inverse(ur5, T, solutions="all").solutions[:2]        # two branches of one tool frame
    wrong = q + [0, 0, 0, 0, 0, 5.0]
    rows = [solution_sets.pose_rows(ur5, "ur5", "analytic", 0, np.stack([q]), T, 1e-3, 1e-3, 1e-2, 1e-2),
            solution_sets.pose_rows(ur5, "ur5", "ref", 0, np.stack([q, q + [360.0, 0, 0, 0, 0, 0], other, wrong]), T,
                                    1e-2, 1e-2, 1e-2, 1e-2),
            solution_sets.pose_rows(ur5, "ur5", "none", 0, None, T, 1e-2, 1e-2, 1e-2, 1e-2)]
    a = pd.concat(rows, ignore_index=True)
    board = solution_sets.solutions_board(a, {"ur5": ur5}, reference="ref", analytic="analytic").set_index("solver")
    assert board.loc["ref", ["answers", "failed", "distinct"]].tolist() == [4, 1, 2]
    assert board.loc["ref", "recall_analytic"] == 1.0 and board.loc["ref", "beyond_analytic"] == 1
    assert board.loc["analytic", "recall_union"] == 0.5 and board.loc["ref", "recall_union"] == 1.0
    assert board.loc["none", "distinct"] == 0 and board.loc["none", "recall_union"] == 0.0


@pytest.mark.skipif(not STORED.is_dir(), reason="the stored quick tier")
def test_fkopt_check_rejudges_the_stored_answers_of_both_tracks(config, tmp_path):
    q = config.quick_tier()
    q._folder = SUITE.parent
    assert reverify(STORED, q) == []
    copy = tmp_path / "stored"
    shutil.copytree(STORED, copy)
    path = copy / "solutions.csv.gz"
    a = pd.read_csv(path)
    k = int(np.flatnonzero(a["copies"] > 0)[0])
    a.loc[k, "q0"] = a.loc[k, "q0"] + 1.0           # an answer moved, its verdict kept
    with gzip.open(path, "wt") as f:
        a.to_csv(f, index=False, float_format="%.17g")
    p = pd.read_csv(copy / "paths.csv.gz")
    with gzip.open(copy / "paths.csv.gz", "wt") as f:
        p.drop(index=3).to_csv(f, index=False, float_format="%.17g")      # a waypoint's answer deleted
    found = reverify(copy, q)
    assert any(f[0] == "solutions.csv.gz" and f[2] in ("position_m", "rotation_rad") for f in found)
    assert any(f[0] == "paths.csv.gz" and f[2] == "rows" for f in found)


@pytest.mark.skipif(not STORED.is_dir(), reason="the stored quick tier")
def test_resume_accepts_a_track_task_file_only_when_every_answer_recomputes(config):
    from fkopt.kinbench.runner import record_problem, suite_plan
    q = config.quick_tier()
    q._folder = SUITE.parent
    plan = suite_plan(q)
    for track, name, stem in (("all-solutions", "z1", "solutions"), ("paths", "z1", "paths")):
        task = next(t for t in plan.tasks if t.payload.get("track") == track
                    and q.problems[t.payload["problem"]].name == name)
        rows = pd.read_csv(STORED / f"{stem}.csv.gz", keep_default_na=False, na_values=[""])
        rows = rows[rows["problem"] == name].dropna(axis=1, how="all").reset_index(drop=True)
        rows["not_applicable"] = ""
        rec = {"fingerprint": plan.fingerprint, "track": track, "problem": task.payload["problem"], "wall_s": 1.0,
               "answers": rows.to_dict(orient="list")}
        assert record_problem(task, rec) is None
        rows.loc[0, "position_m"] = 0.5                 # a verdict that its answer does not give
        assert "position_m" in record_problem(task, {**rec, "answers": rows.to_dict(orient="list")})
