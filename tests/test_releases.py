"""Released kinbench versions are frozen in the code (fkopt.kinbench.releases): the issue's swap of a
v1 pose set with a re-signed manifest is refused, and the fitness definitions keep their numbers."""
import hashlib
import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from fkopt.errors import FkoptError
from fkopt.kinbench.config import load_suite
from fkopt.kinbench.posesets import load_pose_sets, problem_mechanism, targets_of
from fkopt.kinbench.releases import RELEASES, check_release, release_files

ROOT = Path(__file__).resolve().parents[1]
SUITES = ROOT / "configs" / "suites"
RELEASED_SUITES = {"kinbench-v1": "kinbench.yaml", "kinbench-v2": "kinbench-v2.yaml"}
#: Every version whose files are pinned (v3's too: issue 42; its fitness probe is v1/v2's definitions).
PINNED_SUITES = {**RELEASED_SUITES, "kinbench-v3": "kinbench-v3.yaml"}


def copy_suite(tmp_path, suite="kinbench.yaml"):
    for name in ("kinbench-v1", "kinbench-v2", "robots"):
        shutil.copytree(SUITES / name, tmp_path / name)
    shutil.copy(SUITES / suite, tmp_path / suite)
    return tmp_path / suite


def swap_and_resign(folder: Path):
    """The issue's edit: v1's uniform set of mao2017-3rps replaced by the boundary set's bytes and the
    manifest's digest updated, so the manifest alone no longer notices."""
    sets = folder / "kinbench-v1" / "mao2017-3rps"
    (sets / "uniform.csv").write_bytes((sets / "boundary.csv").read_bytes())
    mpath = folder / "kinbench-v1" / "manifest.json"
    manifest = json.loads(mpath.read_text())
    manifest["problems"]["mao2017-3rps"]["sets"]["uniform"]["sha256"] = \
        hashlib.sha256((sets / "uniform.csv").read_bytes()).hexdigest()
    mpath.write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n")


@pytest.mark.parametrize("version, suite", PINNED_SUITES.items())
def test_the_committed_released_suites_match_their_frozen_digests(version, suite):
    cfg = load_suite(SUITES / suite)
    load_pose_sets(cfg)                                    # passes the release check
    assert release_files(cfg) == RELEASES[version].files


def test_a_swapped_pose_set_with_a_resigned_manifest_is_refused_in_one_line(tmp_path, fkopt_run):
    path = copy_suite(tmp_path)
    swap_and_resign(tmp_path)
    with pytest.raises(FkoptError, match=r"uniform.csv: differs from released kinbench-v1") as err:
        load_pose_sets(load_suite(path))
    assert "\n" not in str(err.value) and "new version" in str(err.value)
    out = tmp_path / "out"
    r = fkopt_run("suite", str(path), "--quick", "--out", str(out))
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "released kinbench-v1" in r.stderr, r.stderr
    assert "Traceback" not in r.stderr and not out.exists()


def test_the_same_edit_under_a_new_version_name_is_accepted_and_a_renamed_folder_is_still_checked(tmp_path):
    path = copy_suite(tmp_path)
    swap_and_resign(tmp_path)
    (tmp_path / "kinbench-v1").rename(tmp_path / "my-v1")
    data = yaml.safe_load(path.read_text())
    data["pose_sets"] = "my-v1"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(FkoptError, match="released kinbench-v1"):      # the manifest still says kinbench-v1
        load_pose_sets(load_suite(path))
    mpath = tmp_path / "my-v1" / "manifest.json"
    mpath.write_text(mpath.read_text().replace('"version": "kinbench-v1"', '"version": "my-v1"'))
    sets, manifest = load_pose_sets(load_suite(path))
    assert manifest["version"] == "my-v1"


def test_an_added_file_a_changed_robot_and_another_fitness_version_are_refused(tmp_path, monkeypatch):
    path = copy_suite(tmp_path, "kinbench-v2.yaml")
    (tmp_path / "kinbench-v2" / "extra.csv").write_text("x\n")
    with pytest.raises(FkoptError, match="extra.csv: not part of released kinbench-v2"):
        load_pose_sets(load_suite(path))
    (tmp_path / "kinbench-v2" / "extra.csv").unlink()
    urdf = tmp_path / "robots" / "ur5.urdf"
    urdf.write_text(urdf.read_text().replace("0.089159", "0.08916"))
    with pytest.raises(FkoptError, match="ur5.urdf: differs from released kinbench-v2"):
        load_pose_sets(load_suite(path))
    shutil.copy(SUITES / "robots" / "ur5.urdf", urdf)
    import fkopt.kinbench.releases as R
    monkeypatch.setattr(R, "FITNESS_VERSION", R.FITNESS_VERSION + 1)
    with pytest.raises(FkoptError, match="fitness definitions version 1, this fkopt has version 2"):
        check_release(load_suite(path), {"version": "kinbench-v2"})


#: Fitness of each released problem at its first uniform pose moved by 1 % of the box (the first
#: point of the set after the solution), to 9 significant digits. A change of these numbers is a
#: change of the fitness definitions: a new FITNESS_VERSION and a new kinbench version (CHANGES.md).
FITNESS_AT_PROBE = {
    "mao2017-3rps": 29.9409012,
    "wu2015-3ppr": 5.04736694,
    "chang2024-3rpupc": 7.24294738,
    "liu2008-6sps": 0.0291070527,
    "wang2020-7dof": 81.6840837,
    "dietmaier-6sps": 0.0488976788,
    "ur5": 23.9261186,
    "panda": 9.65498226,
    "kinova-j2s6s200": 5.70367367,
}


def probe_fitness(cfg):
    from fkopt.kinds.experiment.runner import make_problem
    sets, _ = load_pose_sets(cfg)
    out = {}
    for problem in cfg.problems:
        mech, rc = problem_mechanism(problem, cfg._folder)
        x = sets[(problem.name, "uniform")][:1]
        prob = make_problem(rc, mech, targets_of(mech, x))
        step = 0.01 * (mech.bounds[:, 1] - mech.bounds[:, 0])
        out[problem.name] = float(f"{float(prob.fitness((x + step)[:, None])[0, 0]):.9g}")
    return out


def test_fitness_definitions_give_the_released_numbers():
    got = {}
    for suite in RELEASED_SUITES.values():
        got.update(probe_fitness(load_suite(SUITES / suite)))
    print(got)
    assert got == FITNESS_AT_PROBE


def test_fkopt_check_refuses_a_run_whose_released_pose_sets_were_swapped_after_it(tmp_path):
    path = copy_suite(tmp_path)
    data = yaml.safe_load(path.read_text())
    data.update(problems=[p for p in data["problems"] if p["name"] == "mao2017-3rps"], solvers=[{"name": "lm"}],
                poses=1, runs=1, sets=["uniform"], budget_per_dim=20, bootstrap=100, quick=None)
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    env = {"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"}
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "fkopt.cli", "suite", str(path), "--out", str(out), "-q"],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    swap_and_resign(tmp_path)
    r = subprocess.run([sys.executable, "-m", "fkopt.cli", "check", str(out)], capture_output=True, text=True, env=env)
    assert r.returncode != 0 and "released kinbench-v1" in r.stdout + r.stderr, r.stdout + r.stderr
    assert "Traceback" not in r.stderr


def test_freeze_prints_the_release_entry_of_a_suite_and_refuses_bad_usage(capsys):
    from fkopt.kinbench.freeze import main
    assert main(["release", str(SUITES / "kinbench-v2.yaml")]) == 0
    out = capsys.readouterr().out
    assert out.startswith('    "kinbench-v2": Release(fitness=1, files={')
    for name, digest in RELEASES["kinbench-v2"].files.items():
        assert f'        "{name}": "{digest}",' in out
    assert main(["pose-set"]) == 2 and "usage:" in capsys.readouterr().err
    assert main(["release", str(SUITES / "missing.yaml")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1
