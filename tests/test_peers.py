"""Peer configs: valid, outside make reproduce's configs/, and summarised as markdown."""
from pathlib import Path

import pytest

from fkopt.kinds.experiment.config import ExperimentConfig, load_config
from fkopt.kinds.experiment.reports import write_experiment
from fkopt.kinds.experiment.runner import run_experiment, validate_experiment
from fkopt.tools.peers import peers_markdown

ROOT = Path(__file__).resolve().parents[1]
PAPERS = ("mao2017", "liu2008", "wang7dof", "wu2015", "chang2024")


def test_one_peer_config_per_paper_outside_configs():
    files = sorted((ROOT / "peers").glob("*.yaml"))
    assert sorted(f.stem for f in files) == sorted(PAPERS)
    assert not list((ROOT / "configs").rglob("peers*.yaml"))     # make reproduce never sees them
    assert "reproduce-peers:" in (ROOT / "Makefile").read_text()


@pytest.mark.parametrize("paper", PAPERS)
def test_peer_configs_validate(paper):
    pytest.importorskip("pymoo")
    pytest.importorskip("niapy")
    config = load_config(ROOT / "peers" / f"{paper}.yaml")
    validate_experiment(config)
    assert config.paper == paper and config.name == "peers"
    libs = [a for a in config.algorithms if ":" in a.name]
    builtin = [a for a in config.algorithms if ":" not in a.name]
    assert libs and builtin
    for a in libs:            # every library run has an explicit budget
        assert a.params.get("evaluations", 0) > 0


def test_peers_markdown_names_versions_and_compares(tmp_path):
    pytest.importorskip("pymoo")
    cfg = ExperimentConfig(**{
        "name": "peers", "paper": "mao2017", "title": "tiny", "mechanism": {"name": "3-rps"},
        "cases": [{"label": "c", "pose": {"alpha": 9, "beta": 13, "z": 622}}],
        "algorithms": [{"name": "pso"}, {"name": "pymoo:PSO", "label": "pymoo_pso", "params": {"evaluations": 310}}],
        "population": 10, "iterations": 30, "runs": 2, "seed": 1, "threshold": 1e-10})
    write_experiment(run_experiment(cfg), tmp_path)
    md = peers_markdown(tmp_path)
    assert "## mao2017: tiny" in md and "pymoo " in md and "| c | pymoo_pso | `pymoo:PSO` |" in md
    assert "fkopt `pso` vs `pymoo:PSO` (1.000x its evaluations)" in md
    assert "No peer results" in peers_markdown(tmp_path / "empty")
