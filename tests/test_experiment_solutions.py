"""Every solution of each case in an experiment file (issue 40): an exact solver's entry with
``params: {solutions: all}`` writes solutions.csv, which must equal the library called directly
(``fkopt.inverse(arm, pose, solutions="all")`` / the assembly-mode search) with the case's seed,
resume from its task files, and refuse bad values with one line."""
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

import fkopt
from fkopt.errors import FkoptError
from fkopt.kinematics.assembly_modes import all_solutions as assembly_modes
from fkopt.run.pipeline import from_dict, plan_config, run_config
from fkopt.run.solving import task_seed
from fkopt.run.tasks import TASKS
from conftest import interrupted_after_first_task

UR5 = {"name": "urdf", "geometry": {"file": str(Path(__file__).resolve().parents[1] / "configs" / "suites" / "robots"
                                                / "ur5.urdf"), "base": "base_link", "tip": "tool0"}}
UR5_JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
              "wrist_3_joint")
UR5_CASES = [{"joints": dict(zip(UR5_JOINTS, [20.0, -70.0, 60.0, 30.0, 40.0, 50.0]))},
             {"label": "given pose", "pose": {"x": 0.3, "y": 0.2, "z": 0.4, "alpha": 10, "beta": 120, "gamma": 30}}]
SEARCH_FIELDS = ("patience", "max_starts", "starts", "converged", "since_last_new", "evaluations", "distinct",
                 "out_of_limits", "unverified")


def run(cli, tmp_path, config: dict, name: str = "exp.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(config))
    code, out, err = cli("run", path, "--out", tmp_path / "out", "-q")
    assert code == 0, err
    return tmp_path / "out" / "experiments" / config["name"]


def ur5():
    return fkopt.mechanism("urdf", **UR5["geometry"])


def frame_errors(m, q, T):
    """Position and geodesic rotation errors of FK rows against frame T, by the arm's own FK matrix."""
    F = m.fk_matrix(np.atleast_2d(q))
    M = F[:, :3, :3] @ T[:3, :3].T
    return (np.linalg.norm(F[:, :3, 3] - T[:3, 3], axis=1),
            np.arccos(np.clip((np.trace(M, axis1=1, axis2=2) - 1) / 2, -1, 1)))


def test_solutions_csv_equals_fkopt_inverse_called_directly_on_the_ur5(cli, tmp_path):
    """Two UR5 cases (one by joints, one by pose): solutions.csv holds, per case, exactly the rows of
    fkopt.inverse(arm, pose, solutions="all", seed=the case's task seed) -- joints under the joint
    names in degrees, errors, the search's stopping-rule fields -- every row reproduces its target
    (checked by FK here), the generating joints are among case 1's, and without a one-answer entry
    no runs.csv or summary.csv is written."""
    config = {"name": "ur5all", "mechanism": UR5, "cases": UR5_CASES, "seed": 11,
              "algorithms": [{"name": "inverse", "params": {"solutions": "all"}}]}
    folder = run(cli, tmp_path, config)
    table = pd.read_csv(folder / "solutions.csv")
    assert list(table.columns[:3]) == ["case", "algorithm", "solution"]
    assert list(table.columns[3:9]) == list(UR5_JOINTS)
    assert not (folder / "runs.csv").exists() and not (folder / "summary.csv").exists()
    assert {"meta.json", "env.json", "timing.csv"} <= {p.name for p in folder.iterdir()}
    m = ur5()
    targets = [m.fk(np.array(list(UR5_CASES[0]["joints"].values()))),
               np.array([UR5_CASES[1]["pose"][n] for n in m.pose_names])]
    meta = json.loads((folder / "meta.json").read_text())
    for index, (label, target) in enumerate(zip(["case-1", "given pose"], targets)):
        seed = task_seed(11, index, "inverse")
        direct = fkopt.inverse(m, target, solutions="all", seed=seed)
        rows = table[table["case"] == label]
        assert len(direct) >= 4 and len(rows) == len(direct)
        assert rows["solution"].tolist() == list(range(1, len(direct) + 1))
        assert (rows["seed"] == seed).all() and {"case": label, "algorithm": "inverse", "seed": seed} in meta["task_seeds"]
        np.testing.assert_allclose(rows[list(UR5_JOINTS)].to_numpy(), direct.solutions, rtol=1e-11, atol=1e-9)
        np.testing.assert_allclose(rows["position_error"], direct.position_error, rtol=1e-11)
        np.testing.assert_allclose(rows["rotation_error"], direct.rotation_error, rtol=1e-11)
        for field in SEARCH_FIELDS:
            assert (rows[field] == direct.search[field]).all(), field
        # the library's own statement: a certificate (Pieper's bound reached) or the rule it stopped by
        assert (rows["stopping_rule"] == direct.search["rule"]).all()
        dp, dr = frame_errors(m, rows[list(UR5_JOINTS)].to_numpy(), m.fk_matrix(direct.solutions[:1])[0])
        assert (dp < 1e-9).all() and (dr < 1e-7).all()
    first = table[table["case"] == "case-1"][list(UR5_JOINTS)].to_numpy()
    assert np.abs(first - [20.0, -70.0, 60.0, 30.0, 40.0, 50.0]).max(axis=1).min() < 1e-6


def test_a_redundant_arm_with_fixed_and_spread_beside_a_one_answer_entry(cli, tmp_path):
    """The 7-joint DH arm: a fixed entry keeps its locked value in every row and equals the library
    with fixed=; a spread entry equals it with spread=; a one-answer inverse entry beside them fills
    runs.csv and summary.csv alone (the set entries have no runs)."""
    m = fkopt.mechanism("7dof-arm")
    q = dict(zip(m.joint_names, [10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 10.0]))
    config = {"name": "seven", "mechanism": {"name": "7dof-arm"}, "cases": [{"joints": q}], "seed": 4, "runs": 2,
              "iterations": 3,
              "algorithms": [{"name": "inverse", "label": "locked", "params": {"solutions": "all", "fixed": {"q3": 30.0}}},
                             {"name": "inverse", "label": "one"},
                             {"name": "exact", "label": "spread", "params": {"solutions": "all", "spread": 2}}]}
    folder = run(cli, tmp_path, config)
    table = pd.read_csv(folder / "solutions.csv")
    runs = pd.read_csv(folder / "runs.csv")
    assert set(runs["algorithm"]) == {"one"} and len(runs) == 2
    assert set(pd.read_csv(folder / "summary.csv")["algorithm"]) == {"one"}
    target = m.fk(np.array(list(q.values())))
    for label, options in (("locked", {"fixed": {"q3": 30.0}}), ("spread", {"spread": 2})):
        direct = fkopt.inverse(m, target, solutions="all", seed=task_seed(4, 0, label), **options)
        rows = table[table["algorithm"] == label]
        assert len(rows) == len(direct) >= 1
        np.testing.assert_allclose(rows[list(m.joint_names)].to_numpy(), direct.solutions, rtol=1e-11, atol=1e-9)
        assert (rows["starts"] == direct.search["starts"]).all()
    assert np.allclose(table.loc[table["algorithm"] == "locked", "q3"], 30.0)


def test_forward_with_every_solution_is_the_assembly_mode_search(cli, tmp_path):
    """On a parallel mechanism forward/exact with solutions: all route to the assembly-mode search:
    its poses, residuals and hits with the case's seed; fkopt check reruns the file and fails an
    edited residual."""
    config = {"name": "modes", "mechanism": {"name": "3-rps"}, "seed": 2,
              "cases": [{"pose": {"alpha": 9, "beta": 13, "z": 622}}, {"joints": {"d1": 598.85, "d2": 671.92,
                                                                                  "d3": 629.16}}],
              "algorithms": [{"name": "forward", "params": {"solutions": "all"}}]}
    folder = run(cli, tmp_path, config)
    table = pd.read_csv(folder / "solutions.csv")
    m = fkopt.mechanism("3-rps")
    inputs = [m.ik(np.array([9.0, 13.0, 622.0])), np.array([598.85, 671.92, 629.16])]
    for index, (label, joints) in enumerate(zip(["case-1", "case-2"], inputs)):
        direct = assembly_modes(m, joints, seed=task_seed(2, index, "forward"))
        poses = direct.poses()
        order = np.lexsort(poses.T[::-1])
        rows = table[table["case"] == label]
        assert len(rows) == len(direct) >= 1
        np.testing.assert_allclose(rows[list(m.pose_names)].to_numpy(), poses[order], rtol=1e-11)
        assert rows["hits"].tolist() == [direct[i].hits for i in order]
        assert (rows["starts"] == direct.starts).all()
    code, out, err = cli("check", folder)                 # fkopt check reruns it and compares solutions.csv
    assert code == 0, out + err
    path = folder / "solutions.csv"
    lines = path.read_text().splitlines()
    cells = lines[1].split(",")
    cells[lines[0].split(",").index("residual")] = "0.001"
    path.write_text("\n".join([lines[0], ",".join(cells), *lines[2:]]) + "\n")
    code, out, err = cli("check", folder)
    assert code == 1 and "solutions.csv" in out + err


def test_resume_reuses_a_finished_search_and_writes_the_same_file(tmp_path):
    """Stopped after its first entry, the experiment keeps that task file; resume computes only the
    other and writes solutions.csv byte for byte as an uninterrupted run; a record of another
    seed is refused by the plan's check."""
    data = {"name": "two", "paper": "test", "mechanism": UR5, "cases": UR5_CASES[:1], "seed": 5,
            "algorithms": [{"name": "inverse", "label": "a", "params": {"solutions": "all"}},
                           {"name": "inverse", "label": "b", "params": {"solutions": "all", "patience": 16}}]}
    config = from_dict(data, "t")
    whole = run_config(config, tmp_path / "whole")
    interrupted_after_first_task(config, tmp_path / "out")
    tasks = tmp_path / "out" / "test" / ".two.partial" / TASKS
    assert sorted(p.name for p in tasks.iterdir()) == ["a00.json", "manifest.json"]
    again = run_config(config, tmp_path / "out", resume=True)
    assert again.computed == ["a01"]
    assert (again.folder / "solutions.csv").read_bytes() == (whole.folder / "solutions.csv").read_bytes()
    plan = plan_config(config, timing=False)
    rec = json.loads(json.dumps(plan.local(plan.tasks[0].payload)))
    assert plan.check(plan.tasks[0], rec) is None
    assert "algorithm" in plan.check(plan.tasks[1], rec)
    rec["sets"][0]["seed"] += 1
    assert "seed" in plan.check(plan.tasks[0], rec)


SEVEN = {"name": "bad", "mechanism": {"name": "7dof-arm"},
         "cases": [{"joints": {f"q{i}": 10.0 * i for i in range(1, 8)}}], "runs": 2, "iterations": 3}


@pytest.mark.parametrize("change, expected", [
    ({"algorithms": [{"name": "inverse", "params": {"solutions": "some"}}]},
     "algorithm 'inverse' parameter 'solutions': Input should be 'one' or 'all'"),
    ({"algorithms": [{"name": "inverse", "params": {"solutions": "all", "fixed": {"q9": 3}}}]},
     "algorithms[inverse]: 7dof-arm fixed: unknown joint 'q9'; joints: q1, q2, q3, q4, q5, q6, q7"),
    ({"algorithms": [{"name": "inverse", "params": {"solutions": "all"}}]},
     "algorithms[inverse]: 7dof-arm has 7 joints for 6 task components: its solutions are not finite"),
    ({"algorithms": [{"name": "inverse", "params": {"fixed": {"q3": 3}}}]},
     "parameter 'fixed': only with solutions: all"),
    ({"algorithms": [{"name": "pso", "params": {"solutions": "all"}}]},
     "algorithms[pso].params.solutions: only the exact solvers give every solution of a pose (inverse or exact"),
    ({"algorithms": [{"name": "inverse", "start": {f"q{i}": 0 for i in range(1, 8)},
                      "params": {"solutions": "all", "fixed": {"q3": 3}}}]},
     "algorithms[inverse].start: a search of every solution (solutions: all) takes no start"),
    ({"mechanism": {"name": "3-rps"}, "cases": [{"pose": {"alpha": 9, "beta": 13, "z": 622}}],
      "algorithms": [{"name": "inverse", "params": {"solutions": "all"}}]},
     "algorithms[inverse]: algorithm 'inverse' solves inverse kinematics of a serial arm only"),
    ({"mechanism": {"name": "3-rps"}, "cases": [{"pose": {"alpha": 9, "beta": 13, "z": 622}}],
      "algorithms": [{"name": "exact", "params": {"solutions": "all", "spread": 2}}]},
     "algorithms[exact]: spread: options of a serial arm's search; '3-rps' is a parallel mechanism"),
])
def test_bad_values_are_one_line_naming_the_file_and_field(cli, tmp_path, change, expected):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({**SEVEN, **change}))
    code, out, err = cli("run", path, "--out", tmp_path / "out")
    assert code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert f"{path}: " in err and expected in err, err
    assert not (tmp_path / "out").exists()


def test_a_study_and_fkopt_solve_refuse_every_solution():
    study = {"kind": "study", "name": "st", "mechanism": {"name": "7dof-arm"}, "poses": {"uniform": 2, "seed": 1},
             "algorithms": [{"name": "inverse", "params": {"solutions": "all", "fixed": {"q3": 0}}}],
             "population": 4, "iterations": 2, "runs": 1}
    with pytest.raises(FkoptError, match=r"algorithms\[inverse\]\.params\.solutions: 'all' .* experiment files"):
        plan_config(from_dict(study, "st.yaml"), "st.yaml")
    m = fkopt.mechanism("7dof-arm")
    problem = fkopt.ik_problem(m, m.fk(m.bounds.mean(axis=1)))
    with pytest.raises(FkoptError, match="not one answer per run"):
        fkopt.solve(problem, "inverse", params={"solutions": "all", "fixed": {"q3": 0.0}})
