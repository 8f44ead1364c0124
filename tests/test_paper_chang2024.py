"""chang2024 reproduction: configs, the printed case, a small run of each config kind, claims."""
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from fkopt.kinds.experiment.config import ExperimentConfig, load_config
from fkopt.kinds.experiment.reports import write_tables
from fkopt.kinds.experiment.runner import run_experiment, validate_experiment
from fkopt.problems import fk_problem
from fkopt.registry import mechanism_class
from fkopt.reproduce import PAPERS, chang2024
from fkopt.reproduce.claims import NOT_CHECKABLE
from fkopt.reproduce.store import Store
from fkopt.reproduce.engine import info, judge_paper

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = [p for p in sorted((ROOT / "configs" / "chang2024").glob("*.yaml")) if p.name != "claims.yaml"]

def _claims(paper, store):
    return judge_paper(paper, store)[0]


def _timing(paper, store):
    return judge_paper(paper, store)[1]



def test_registered_and_every_experiment_has_a_config():
    assert PAPERS["chang2024"] == "fkopt.reproduce.chang2024"
    names = {load_config(p).name for p in CONFIGS}
    assert names == set(info("chang2024")["experiments"])


@pytest.mark.parametrize("path", CONFIGS, ids=[p.stem for p in CONFIGS])
def test_configs_validate_with_printed_settings(path):
    cfg = load_config(path)
    assert cfg.paper == "chang2024" and cfg.mechanism.name == "3-rpupc-ups"
    validate_experiment(cfg)
    assert cfg.population == 100 and cfg.iterations == 300
    for a in cfg.algorithms:
        if a.name in ("pso", "pabc"):
            assert (a.params["w"], a.params["c1"], a.params["c2"]) == (0.8, 2, 2)
        if a.name == "pabc":
            assert a.params["switch"] == 0.5
    if cfg.name == "tab1_fig7":
        assert cfg.runs == 30 and cfg.check == "ci"
    if cfg.name == "tab2":
        assert cfg.cases.random == 50 and "cases" in cfg.figures


def test_printed_case_inputs_and_exact_solution():
    mech = mechanism_class("3-rpupc-ups")()
    pose = np.array([25.0, 34.0, 23.0, 360.0])
    joints = mech.ik(pose)
    np.testing.assert_allclose(joints[:3], [332.048, 390.904, 402.294], atol=5e-4)
    assert abs(joints[3] - (-14.4389)) < 5e-5
    assert mech.in_bounds(pose)
    prob = fk_problem(mech, joints)
    assert prob.fitness(pose) == 0.0
    # the printed (rounded) inputs are 1e-3-close, so the fitness of the pose against them is tiny
    printed = fk_problem(mech, [332.048, 390.904, 402.294, -14.4389])
    assert printed.fitness(pose) < 1e-6
    table = chang2024.inputs_table()
    assert (table.difference.abs() < 5e-4).all()


def _small(path, tmp_path, **over):
    data = yaml.safe_load(Path(path).read_text())
    data.update(over)
    cfg = ExperimentConfig(**data)
    er = run_experiment(cfg, source=str(path))
    folder = tmp_path / "chang2024" / cfg.name
    folder.mkdir(parents=True)
    return write_tables(er, folder)


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    root = tmp_path_factory.mktemp("results")
    cfg = ROOT / "configs" / "chang2024"
    files = {
        "tab1_fig7": _small(cfg / "tab1_fig7.yaml", root, runs=3, iterations=20, population=20),
        "tab2": _small(cfg / "tab2.yaml", root, cases={"random": 3, "seed": 1}, iterations=20, population=20),
        "baselines": _small(cfg / "baselines.yaml", root, runs=2, iterations=20, population=20),
    }
    return Store(root), files


def test_small_runs_write_the_expected_files(store):
    st, files = store
    assert {"summary.csv", "timing.csv", "values.csv", "runs.csv", "trace.csv.gz", "fig7.png", "fig7.pdf"} <= set(
        files["tab1_fig7"])
    assert {"tab2_poses.png", "tab2_poses_time.png"} <= set(files["tab2"])
    assert "trace.csv.gz" in files["tab2"]
    s = st.get("chang2024", "tab1_fig7").table("summary")
    assert list(s.algorithm) == ["abc", "pso", "pabc"]
    assert "printed_error_order" in s.columns
    # P-ABC: PSO for half the iterations (population evaluations), ABC after (about twice that)
    ev = s.set_index("algorithm").mean_evaluations
    assert ev["pso"] < ev["pabc"] < ev["abc"]
    t2 = st.get("chang2024", "tab2").table("summary")
    assert t2["case"].nunique() == 3


def test_extra_tables_and_claims_run(store):
    st, _ = store
    for name in info("chang2024")["experiments"]:
        for caption, df in chang2024.extra_tables(st.get("chang2024", name)):
            assert isinstance(caption, str) and isinstance(df, pd.DataFrame) and not df.empty
    poses = chang2024.poses_table(st.get("chang2024", "tab2"))
    assert len(poses) == 3 and {"fitness_abc", "fitness_pso", "fitness_pabc"} <= set(poses.columns)
    claims = {c.id: c for c in _claims("chang2024", st)}
    inputs = claims["case-inputs"]   # the reconstructed model was built to reproduce this case: circular
    assert inputs.verdict == NOT_CHECKABLE and "reconstructed mechanism" in inputs.condition
    assert inputs.evidence.startswith("circular")
    assert abs(inputs.numbers["difference_l1"] - 3.5e-4) < 1e-5 and abs(inputs.numbers["difference_delta"]) < 5e-5
    # the error measure f_PS was lost: absolute error levels cannot be judged
    assert claims["tab1-orders"].verdict == NOT_CHECKABLE
    # comparisons are rank tests at equal iterations with equal evaluations beside, on the lost P-ABC's reconstruction
    better = claims["tab1-pabc-vs-abc"]
    assert 0 <= better.numbers["p_abc"] <= 1 and 0 <= better.numbers["p_evaluations_abc"] <= 1
    assert better.verdict == ("conditional: held" if better.numbers["lower_abc"] == "P-ABC" else "conditional: not held")


def test_claims_without_results_are_not_checkable(tmp_path):
    from fkopt.reproduce import paper_module
    from fkopt.reproduce.engine import judge, load
    store = Store(tmp_path)
    assert judge_paper("chang2024", store) is None    # a tree without its experiments gets no verdict files
    claims = [c for spec in load("chang2024")["claims"] if spec["kind"] != "timing"
              for c in judge("chang2024", spec, store, paper_module("chang2024"))]
    assert claims[0].evidence.startswith("circular")          # the inverse map needs no results, but is circular
    assert all(c.verdict == NOT_CHECKABLE for c in claims)
