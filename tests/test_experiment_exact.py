"""The exact solvers (`forward`, `inverse`, `exact`) as algorithms of an experiment file, run
through `fkopt run` (issue 32: they used to end with "has a single target"), every answer checked
by a map that is not the solver's: the 3-RPS closed-form inverse map for FK, pinocchio's own URDF
reader and FK for the Panda's IK."""
import numpy as np
import pandas as pd
import pytest
import yaml

import fkopt

ROBOTS = __import__("pathlib").Path(__file__).resolve().parents[1] / "configs" / "suites" / "robots"


def run(cli, tmp_path, config: dict):
    path = tmp_path / "exp.yaml"
    path.write_text(yaml.safe_dump(config))
    code, out, err = cli("run", path, "--out", tmp_path / "out", "-q")
    assert code == 0, err
    return pd.read_csv(tmp_path / "out" / "experiments" / config["name"] / "runs.csv")


def test_forward_and_exact_in_an_experiment_solve_3rps_fk(cli, tmp_path):
    poses = [{"alpha": 9, "beta": 13, "z": 622}, {"alpha": -5, "beta": 3, "z": 600}]
    runs = run(cli, tmp_path, {"name": "fk", "mechanism": {"name": "3-rps"}, "cases": [{"pose": p} for p in poses],
                               "algorithms": [{"name": "forward"}, {"name": "exact"}], "runs": 2, "iterations": 5})
    assert sorted(runs.algorithm.unique()) == ["exact", "forward"] and len(runs) == 2 * 2 * 2
    m = fkopt.mechanism("3-rps")
    for (case, _), group in runs.groupby(["case", "algorithm"], sort=False):
        target = poses[int(case.split("-")[1]) - 1]
        x = group[[f"x_{n}" for n in m.unknown_names]].to_numpy()
        # the answer's legs equal the legs of the generating pose (closed-form inverse map)
        np.testing.assert_allclose(m.ik(x), np.broadcast_to(m.ik(np.array([target[n] for n in m.unknown_names])),
                                                               (len(x), 3)), atol=1e-8)
        assert (group.evaluations > 0).all()


def test_inverse_in_an_experiment_solves_panda_ik_checked_by_pinocchio(cli, tmp_path):
    pin = pytest.importorskip("pinocchio")
    q = {f"panda_joint{i}": v for i, v in enumerate([10, -20, 30, -90, 15, 80, 40], start=1)}
    geometry = {"file": str(ROBOTS / "panda.urdf"), "base": "panda_link0", "tip": "panda_hand_tcp"}
    runs = run(cli, tmp_path, {"name": "ik", "mechanism": {"name": "urdf", "geometry": geometry},
                               "cases": [{"joints": q}], "algorithms": [{"name": "inverse"}], "runs": 2,
                               "iterations": 5})
    model = pin.buildModelFromUrdf(geometry["file"])
    data = model.createData()
    frame = model.getFrameId("panda_hand_tcp")

    def pose(joints_deg):
        x = pin.neutral(model)
        for name, v in joints_deg.items():
            x[model.joints[model.getJointId(name)].idx_q] = np.radians(v)
        pin.framesForwardKinematics(model, data, x)
        return data.oMf[frame].copy()

    target = pose(q)
    for _, row in runs.iterrows():
        got = pose({n: row[f"x_{n}"] for n in q})
        assert np.linalg.norm(got.translation - target.translation) < 1e-6            # m
        assert np.linalg.norm(pin.log3(got.rotation.T @ target.rotation)) < 1e-6     # rad


def test_an_empty_joints_mapping_of_a_serial_case_is_one_line(cli, tmp_path):
    path = tmp_path / "e.yaml"
    path.write_text(yaml.safe_dump({"name": "e", "mechanism": {"name": "7dof-arm"}, "cases": [{"joints": {}}],
                                    "algorithms": [{"name": "inverse"}]}))
    code, out, err = cli("run", path, "--out", tmp_path / "out")
    assert code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert "cases[0].joints: missing q1" in err and not (tmp_path / "out").exists()


def test_progress_moves_inside_a_task_and_prints_plain_lines_without_a_terminal(cli, tmp_path, monkeypatch):
    """Issue 32: one task (one algorithm on all cases) used to leave the bar at 0/1 until it ended,
    and without a terminal nothing was printed. Inside the task the iterations tick
    (fkopt.progress), and a stdout that is not a terminal gets plain lines with the time left."""
    import fkopt.cli.display
    import fkopt.run.tasks
    monkeypatch.setattr(fkopt.cli.display, "HEARTBEAT_S", 0.0)
    monkeypatch.setattr(fkopt.run.tasks, "RUNNING_EVERY_S", 0.0)
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump({"name": "p", "mechanism": {"name": "3-rps"}, "cases": {"random": 3, "seed": 1},
                                    "algorithms": [{"name": "gabc"}], "runs": 2, "iterations": 40}))
    code, out, err = cli("run", path, "--out", tmp_path / "out")
    assert code == 0, err
    lines = [ln for ln in out.splitlines() if " tasks (gabc), about " in ln]
    fractions = [float(ln.split(": ")[1].split("/")[0]) for ln in lines]
    assert any(0 < f < 1 for f in fractions), lines          # heard from inside the one task
    assert fractions == sorted(fractions) and all(ln.endswith(" left") for ln in lines)


def test_ticks_map_a_chunk_onto_its_share_of_the_batch():
    from fkopt.progress import listening, part, tick
    heard = []
    with listening(heard.append):
        with part(0.5, 1.0):
            tick(1, 4)
        tick(3, 3)
    tick(1, 2)                                                # nobody listening: nothing
    assert heard == [0.625, 1.0]


@pytest.mark.parametrize("edit, expected", [
    ({"algoritms": [{"name": "gabc"}]}, "algoritms: unknown field (did you mean 'algorithms'?)"),
    ({"algorithms": [{"name": "gabc", "populaton": 3}]},
     "algorithms[0].populaton: unknown field (did you mean 'population'?)"),
    ({"cases": {"random": 3, "sed": 2}}, "cases.sed: unknown field (did you mean 'seed'?)"),
    ({"cases": [{"pose": {"alpha": 9, "beta": 13, "z": 622}}, {"random": 3}]},
     "cases: item 1 is {random: ...}: cases is either a list of cases"),
])
def test_unknown_fields_name_the_closest_and_case_forms_do_not_mix(cli, tmp_path, edit, expected):
    config = {"name": "t", "mechanism": {"name": "3-rps"}, "cases": [{"pose": {"alpha": 9, "beta": 13, "z": 622}}],
              "algorithms": [{"name": "gabc"}]}
    config.update(edit)
    if "algoritms" in edit:
        del config["algorithms"]
    path = tmp_path / "t.yaml"
    path.write_text(yaml.safe_dump(config))
    code, out, err = cli("run", path, "--out", tmp_path / "out")
    assert code == 2 and err.strip().count("\n") == 0 and expected in err, err
    assert not (tmp_path / "out").exists()


def test_study_and_suite_fields_get_the_hint_too():
    from fkopt.errors import FkoptError
    from fkopt.kinbench.config import suite_from_dict
    from fkopt.kinds.study.config import study_from_dict
    with pytest.raises(FkoptError, match=r"budget_per_dm: unknown field \(did you mean 'budget_per_dim'\?\)"):
        suite_from_dict({"kind": "suite", "name": "s", "problems": [], "solvers": [], "budget_per_dm": 3}, "s.yaml")
    with pytest.raises(FkoptError, match=r"\(did you mean 'threshold'\?\)"):
        study_from_dict({"kind": "study", "name": "s", "mechanism": {"name": "3-rps"}, "thresold": 1e-3,
                         "poses": {"uniform": 5}, "algorithms": [{"name": "gabc"}]}, "s.yaml")


def test_a_rerun_with_another_config_names_the_field_that_changed(cli, tmp_path):
    config = {"name": "c", "mechanism": {"name": "3-rps"}, "cases": [{"pose": {"alpha": 9, "beta": 13, "z": 622}}],
              "algorithms": [{"name": "gabc", "population": 4}], "runs": 2, "iterations": 5}
    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(config))
    assert cli("run", path, "--out", tmp_path / "out", "-q")[0] == 0
    config["runs"] = 3
    config["algorithms"][0]["population"] = 6
    path.write_text(yaml.safe_dump(config))
    code, out, err = cli("run", path, "--out", tmp_path / "out", "-q")
    assert code == 2 and "algorithms[0].population: 4 -> 6; runs: 2 -> 3); rerun with --force" in err, err
