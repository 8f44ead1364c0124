"""A newcomer's first hour on a fresh clone (issue 41): the first command leaves `git status`
clean, `fkopt ik` takes the rotations URDF users write, Ctrl-C names the command that resumes,
`fkopt list` fits a screen, mistakes get a "did you mean"."""
import hashlib
from pathlib import Path

import yaml
from conftest import wait_while_running


def _tree(root: Path) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file()}


def test_reproduce_writes_a_folder_of_its_own_and_compares_with_the_stored_results(tmp_path, monkeypatch, cli):
    """Without --out, `fkopt reproduce` writes fkopt-results/reproduce/ (git-ignored) and leaves
    the stored results/ byte for byte; its last lines compare the two and name the command that
    rewrites results/."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "configs" / "mini").mkdir(parents=True)
    (tmp_path / "configs" / "mini" / "a.yaml").write_text(yaml.safe_dump(
        {"paper": "mini", "name": "a", "mechanism": {"name": "3-rps"}, "iterations": 20, "runs": 2, "seed": 4,
         "cases": [{"pose": {"alpha": 5, "beta": 3, "z": 600}}], "algorithms": [{"name": "gabc"}]}))
    code, out, err = cli("reproduce", "--out", "results", "--jobs", "1", "-q")     # make reproduce
    assert code == 0, err
    stored = _tree(tmp_path / "results")
    assert "mini/a/summary.csv" in stored
    code, out, err = cli("reproduce", "--jobs", "1", "-q")
    assert code == 0, err
    assert _tree(tmp_path / "results") == stored                       # the tracked results untouched
    mine = tmp_path / "fkopt-results" / "reproduce"
    assert (mine / "mini" / "a" / "summary.csv").read_bytes() == (tmp_path / "results/mini/a/summary.csv").read_bytes()
    assert (mine / "REPORT.md").is_file() and (mine / "CHANGES.md").is_file()
    assert "every deterministic file is byte-identical to the stored one" in out
    assert "--out results rewrites it" in out


def test_gitignore_covers_what_readmes_first_command_writes():
    root = Path(__file__).resolve().parent.parent
    ignored = (root / ".gitignore").read_text().splitlines()
    assert "/fkopt-results/" in ignored
    from fkopt.cli.entry_point import DEFAULT_OUT
    assert Path("fkopt-results/reproduce").parts[0] == DEFAULT_OUT.name


def _interrupted(tmp_path, command, config, *extra):
    """Run `fkopt COMMAND c.yaml --out OUT -q EXTRA` in its own process group, send it a real
    SIGINT once it computes, and return (exit status, stderr, OUT)."""
    import os
    import signal
    import subprocess
    import sys
    import time
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(Path(__file__).resolve().parents[1]),
                                                                         os.environ.get("PYTHONPATH")]))}
    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml.safe_dump(config))
    out = tmp_path / "out"
    p = subprocess.Popen([sys.executable, "-m", "fkopt.cli", command, str(cfg), "--out", str(out), "-q", *extra],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True, env=env)
    wait_while_running(p, lambda: list(out.glob("*/.*.lock")), 120)   # until it computes (it holds OUT/<paper>/.<name>.lock)
    time.sleep(0.5)
    assert p.poll() is None, "the run finished before it could be interrupted; make it slower"
    os.killpg(p.pid, signal.SIGINT)
    _, err = p.communicate(timeout=60)
    return p.returncode, err, cfg, out


def test_ctrl_c_of_a_fresh_experiment_names_the_command_that_resumes_it(tmp_path):
    code, err, cfg, out = _interrupted(tmp_path, "run", {
        "name": "slow", "paper": "mine", "mechanism": {"name": "3-rps"}, "seed": 1,
        "cases": [{"pose": {"alpha": 9, "beta": 13, "z": 622}}], "algorithms": [{"name": "abc"}, {"name": "pso"}],
        "population": 40, "iterations": 3000, "runs": 60})
    assert code == 130 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err[-500:]
    # experiments keep their finished tasks like studies and suites (issue 39)
    assert f"the finished tasks of this experiment are kept: fkopt run {cfg} --out {out} --resume continues" in err
    assert (out / "mine" / ".slow.partial").is_dir()      # what --resume reuses
    assert not (out / "mine" / "slow").exists()


def test_ctrl_c_of_a_study_names_the_command_that_resumes_it(tmp_path):
    code, err, cfg, out = _interrupted(tmp_path, "study", {
        "kind": "study", "name": "slow", "mechanism": {"name": "3-rps"}, "poses": {"uniform": 400, "seed": 1},
        "algorithms": [{"name": "gabc"}], "population": 20, "iterations": 400, "runs": 5, "seed": 1, "chunk": 40})
    assert code == 130 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err[-500:]
    assert f"the finished tasks of this study are kept: fkopt study {cfg} --out {out} --resume continues" in err
    assert (out / "studies" / ".slow.partial").is_dir()      # what --resume reuses


def test_resume_hint_names_the_suite_command_with_its_tier():
    from types import SimpleNamespace

    from fkopt.cli.entry_point import DEFAULT_OUT
    from fkopt.cli.running import resume_hint
    suite = SimpleNamespace(kind="suite")
    assert resume_hint("suite", "s.yaml", suite, DEFAULT_OUT, quick=True) == \
        "the finished tasks of this suite are kept: fkopt suite s.yaml --quick --resume continues"
    assert resume_hint("run", "a.yaml", SimpleNamespace(kind="assembly"), Path("o"), stored=False) == \
        "an assembly keeps no finished tasks: fkopt run a.yaml --out o starts it again"


def _frame(arm, q):
    import numpy as np
    return np.asarray(arm.fk_matrix(np.asarray(q, dtype=float))).reshape(4, 4)


def test_ik_on_an_arm_takes_roll_pitch_yaw_a_quaternion_or_zyz_angles(cli):
    """The same tip frame given three ways (roll/pitch/yaw and the quaternion by scipy, the Z-Y-Z
    angles by fkopt fk) is reached each time: fk of each answer is that frame."""
    import json

    import numpy as np
    from scipy.spatial.transform import Rotation

    import fkopt
    arm = fkopt.mechanism("urdf")                     # wang7dof's arm as URDF (metres)
    T = _frame(arm, [10, 20, 30, 40, 50, 60, 70])
    xyz = dict(zip("xyz", T[:3, 3].tolist()))
    r = Rotation.from_matrix(T[:3, :3])
    yaw, pitch, roll = r.as_euler("ZYX", degrees=True).tolist()     # intrinsic Z-Y-X: Rz(yaw) Ry(pitch) Rx(roll)
    qx, qy, qz, qw = r.as_quat().tolist()
    code, out, err = cli("fk", "urdf", "--joints", ",".join(f"q{i + 1}={v}" for i, v in
                                                             enumerate([10, 20, 30, 40, 50, 60, 70])), "--json")
    assert code == 0, err
    zyz = {k: v for k, v in json.loads(out)["pose"].items() if k in ("alpha", "beta", "gamma")}
    for rotation in ({"roll": roll, "pitch": pitch, "yaw": yaw}, {"qw": qw, "qx": qx, "qy": qy, "qz": qz}, zyz):
        pose = ",".join(f"{k}={v!r}" for k, v in {**xyz, **rotation}.items())
        code, out, err = cli("ik", "urdf", "--pose", pose, "--json")
        assert code == 0, (rotation, err)
        answer = json.loads(out)
        got = _frame(arm, list(answer["joints"].values()))
        assert np.abs(got[:3, 3] - T[:3, 3]).max() < 1e-6
        assert Rotation.from_matrix(got[:3, :3].T @ T[:3, :3]).magnitude() < 1e-6
        assert answer["solved"] and answer["rotation_error_rad"] < 1e-6


def test_ik_help_states_each_rotation(cli):
    code, out, _ = cli("ik", "--help")
    text = " ".join(out.replace("│", " ").split())
    for words in ("roll, pitch, yaw", "R = Rz(yaw) Ry(pitch) Rx(roll)", "qw, qx, qy, qz", "alpha, beta, gamma",
                  "Z-Y-Z"):
        assert words in text, words


def test_ik_with_a_position_mask_needs_no_angles_and_reports_no_rotation_error(cli):
    import json

    import numpy as np

    import fkopt
    arm = fkopt.mechanism("urdf")
    T = _frame(arm, [10, 20, 30, 40, 50, 60, 70])
    pose = ",".join(f"{k}={v!r}" for k, v in zip("xyz", T[:3, 3].tolist()))
    code, out, err = cli("ik", "urdf", "--pose", pose, "--mask", "x,y,z", "--json")
    assert code == 0, err
    answer = json.loads(out)
    assert "rotation_error_rad" not in answer and answer["solved"]
    assert np.abs(_frame(arm, list(answer["joints"].values()))[:3, 3] - T[:3, 3]).max() < 1e-6
    code, out, err = cli("ik", "urdf", "--pose", pose, "--mask", "x,y,z")
    assert code == 0 and "rotation_error" not in out
    code, out, err = cli("ik", "urdf", "--pose", pose)          # the rotation counts: it is asked for
    assert code == 2 and "missing the rotation" in err and "--mask x,y,z" in err


def test_ik_rotation_mistakes_are_one_line(cli):
    base = "x=0.1,y=0.2,z=0.3"
    for extra, words in ((",roll=1,alpha=2,beta=0,gamma=0", "give one rotation"),
                         (",rol=1,pitch=2,yaw=3", "did you mean 'roll'?"),
                         (",roll=1", "missing pitch, yaw"),
                         (",qw=0.5,qx=0,qy=0,qz=0", "unit quaternion")):
        code, out, err = cli("ik", "urdf", "--pose", base + extra)
        assert code == 2 and words in err and len(err.strip().splitlines()) == 1, (extra, err)


def _config(tmp_path, text):
    path = tmp_path / "c.yaml"
    path.write_text("name: c\nmechanism: {name: 3-rps}\ncases:\n  - pose: {alpha: 9, beta: 13, z: 622}\n" + text)
    return path


def test_misspelt_algorithm_and_parameter_names_get_a_did_you_mean(tmp_path, cli):
    code, _, err = cli("run", _config(tmp_path, "algorithms: [{name: gabcc}]\n"), "--out", tmp_path / "o")
    assert code == 2 and "unknown algorithm 'gabcc' (did you mean 'gabc'?)" in err
    code, _, err = cli("run", _config(tmp_path, "algorithms: [{name: gabc, params: {limt: 3}}]\n"),
                       "--out", tmp_path / "o")
    assert code == 2 and "parameter 'limt': unknown parameter (did you mean 'limit'?)" in err
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").iterdir())


def test_error_paths_are_written_one_way(tmp_path, cli):
    """A pydantic field path and fkopt's own checks both write list items as [i]."""
    path = tmp_path / "c.yaml"
    path.write_text("name: c\nmechanism: {name: 3-rps}\ncases:\n  - poze: {alpha: 9, beta: 13, z: 622}\n"
                    "algorithms: [{name: gabc}]\n")
    code, _, err = cli("run", path, "--out", tmp_path / "o")
    assert code == 2 and "cases[0].poze: unknown field (did you mean 'pose'?)" in err, err
    path.write_text("name: c\nmechanism: {name: 3-rps}\ncases:\n  - pose: {alpha: 9, beta: 13, zz: 622}\n"
                    "algorithms: [{name: gabc}]\n")
    code, _, err = cli("run", path, "--out", tmp_path / "o")
    assert code == 2 and "cases[0].pose: unknown variable 'zz' (did you mean 'z'?)" in err, err


def test_a_quoted_number_is_refused_with_one_line_and_1e_minus_10_is_a_number(tmp_path, cli):
    for text, words in (('iterations: "300"\n', "iterations: needs a number, got the text '300' (write it "
                                                "without quotes)"),
                        ("algorithms: [{name: gabc, params: {limit: '3'}}]\n", "parameter 'limit': needs a number"),
                        ('threshold: "nan"\n', "threshold: needs a number (finite)")):
        body = text if text.startswith("algorithms") else "algorithms: [{name: gabc}]\n" + text
        code, _, err = cli("run", _config(tmp_path, body), "--out", tmp_path / "o")
        assert code == 2 and words in err and len(err.strip().splitlines()) == 1, (text, err)
    path = tmp_path / "c.yaml"
    path.write_text(path.read_text().replace('threshold: "nan"', "threshold: 1e-10\niterations: 3\nruns: 2"))
    from fkopt.kinds.experiment.config import load_config
    assert load_config(path).threshold == 1e-10                  # YAML 1.2's float without a dot


def test_fkopt_list_piped_fits_a_screen_and_long_has_the_detail(cli):
    import json
    code, out, _ = cli("list")
    assert code == 0 and len(out.splitlines()) <= 20
    names = json.loads(cli("list", "--json")[1])
    for name in names["mechanisms"] + [n for n in names["algorithms"] if not n.startswith("niapy:")]:
        assert name in out, name                                # every name, by kind
    assert "parallel (fk): 3-rps" in out and "local:" in out and "swarm + local:" in out
    code, detail, _ = cli("list", "--long")
    assert code == 0 and "C=1.5" in detail and "built-in" in detail   # parameters and origins


def test_fkopt_list_urdf_with_a_users_geometry_does_not_call_it_the_default(tmp_path, cli):
    from fkopt.mechanisms.urdf import DEFAULT_FILE
    (tmp_path / "arm.urdf").write_text(DEFAULT_FILE.read_text())
    (tmp_path / "arm.yaml").write_text("file: arm.urdf\ntip: tool\n")
    code, out, err = cli("list", "urdf", "--geometry", tmp_path / "arm.yaml")
    assert code == 0, err
    text = " ".join(out.split())
    assert "default geometry (override" not in text and "geometry: the defaults with the values of" in text
    code, out, _ = cli("list", "urdf")
    assert "default geometry (override" in " ".join(out.split())


def test_every_count_of_v3_arms_is_the_count_of_the_suite_files():
    """Suite titles, docs/kinbench.md and README say how many arms, and of which format, the
    suite files hold (they said 22, 23 and 24 of one suite); the robots board says of how many."""
    import re

    from fkopt.kinbench.config import load_suite
    root = Path(__file__).resolve().parent.parent
    v3 = load_suite(root / "configs/suites/kinbench-v3.yaml")
    robots = load_suite(root / "configs/suites/kinbench-v3-robots.yaml")

    def arms(suite):
        kinds = [p.mechanism.name for p in suite.problems]
        return kinds.count("urdf") + kinds.count("mjcf"), kinds.count("urdf"), kinds.count("mjcf")
    n, urdf, mjcf = arms(v3)
    assert f"{n} real arms ({urdf} URDF, {mjcf} MJCF)" in v3.title
    m, urdf_b, mjcf_b = arms(robots)
    assert f"{m} of v3's {n} real arms ({urdf_b} URDF, {mjcf_b} MJCF)" in robots.title
    docs = (root / "docs/kinbench.md").read_text()
    assert f"| real arms | {n} ({urdf} URDF, {mjcf} MJCF)" in docs
    assert f"{m}\nof v3's real arms ({urdf_b} URDF, {mjcf_b} MJCF)" in docs or \
        f"{m} of v3's real arms ({urdf_b} URDF, {mjcf_b} MJCF)" in " ".join(docs.split())
    readme = " ".join((root / "README.md").read_text().split())
    assert f"adds {n} real arms" in readme
    assert "The full tier was not run" not in docs                    # it is stored (README says so)
    assert not re.findall(r"^#+ .*\(issue \d+", docs, flags=re.M)    # titles say what, not which issue
    assert "quick tier: 13 of its 92 problems" in v3.quick_tier().title


def test_ci_runs_readmes_test_command_and_it_uses_both_cores():
    root = Path(__file__).resolve().parent.parent
    lines = (root / "README.md").read_text().splitlines()
    block = lines[lines.index("```bash") + 1:lines.index("```")]
    command = block[1].split("#")[0].strip()
    assert command == ".venv/bin/python -m pytest"
    ci = [line.strip() for line in (root / ".ci" / "run").read_text().splitlines()]
    assert command in ci                                              # exactly README's command
    import tomllib
    project = tomllib.loads((root / "pyproject.toml").read_text())
    assert "-n 2" in project["tool"]["pytest"]["ini_options"]["addopts"]
    assert any(d.startswith("pytest-xdist") for d in project["project"]["optional-dependencies"]["test"])
    assert "chromium-driver" in " ".join(lines)                       # how to run the browser test


def test_summary_rows_over_many_cases_say_the_success_of_all_runs_and_print_no_nan():
    """10 cases, one of which some runs solve: the row's success is the fraction of all runs
    (it printed the median of the cases' rates, 0, beside the median iterations 293 of that one
    case); a case no run solved has no iterations to the threshold: '-', not 'nan'."""
    import numpy as np
    import pandas as pd

    from fkopt.cli.display import SHORT, summary_rows
    df = pd.DataFrame({"case": [f"c{i}" for i in range(10)], "algorithm": "gabc",
                       "median_fitness": 1.0, "success_rate": [0.5] + [0.0] * 9,
                       "median_iterations_to_threshold": [293.0] + [np.nan] * 9})
    cols = [c for c in ("case", "algorithm", *SHORT) if c in df]
    rows, notes = summary_rows(df, cols)
    assert rows == [["all 10 cases", "gabc", "1", "0.05", "293"]]
    assert "fraction of all runs" in notes[0]
    rows, notes = summary_rows(df.iloc[1:3], cols)          # few cases: one row each
    assert rows[0] == ["c1", "gabc", "1", "0", "-"] and any(n.startswith("-: no value") for n in notes)


def test_time_figures_start_their_axis_at_zero(tmp_path, monkeypatch):
    """chang2024 Tab. 2's time per pose started at 30 ms, drawing a 32 vs 80 ms gap as 1 to 25."""
    import yaml

    from fkopt.kinds.experiment import reports
    from fkopt.run.pipeline import load_any, run_config
    seen = {}
    real = reports._save

    def save(fig, path):
        seen[path.stem] = fig.axes[0].get_ylim()
        return real(fig, path)
    monkeypatch.setattr(reports, "_save", save)
    cfg = tmp_path / "t.yaml"
    cfg.write_text(yaml.safe_dump({"name": "t", "mechanism": {"name": "3-rps"}, "iterations": 10, "runs": 2,
                                   "cases": {"random": 2, "seed": 1}, "figures": ["cases", "time"],
                                   "algorithms": [{"name": "gabc"}, {"name": "pso"}]}))
    run_config(load_any(cfg), tmp_path / "out", source=str(cfg))
    times = {k: v for k, v in seen.items() if k.endswith("time")}
    assert times and all(low == 0 for low, _ in times.values()), seen


def test_every_frozen_arm_pose_lies_within_the_arms_limits_as_read_now():
    """The released v2/v3 pose sets were drawn when URDF limits were rounded to the nearest;
    the generator still draws in that box (they regenerate bit for bit) and clips to the arm's
    bounds. No frozen joint lies in the sliver between: every one is inside the bounds fkopt
    reads now, which never lie outside the files' limits."""
    import numpy as np

    from fkopt.kinbench.config import load_suite
    from fkopt.kinbench.posesets import load_pose_sets, problem_mechanism
    from fkopt.mechanisms.urdf import URDFArm
    root = Path(__file__).resolve().parent.parent / "configs" / "suites"
    checked = 0
    for suite in ("kinbench-v2.yaml", "kinbench-v3.yaml"):
        cfg = load_suite(root / suite)
        sets, _ = load_pose_sets(cfg)
        for problem in cfg.problems:
            mech, _ = problem_mechanism(problem, root)
            if not isinstance(mech, URDFArm):
                continue
            for (name, _set), pts in sets.items():
                if name == problem.name and len(pts):
                    assert (pts >= mech.bounds[:, 0]).all() and (pts <= mech.bounds[:, 1]).all(), (name, _set)
                    checked += 1
    assert checked > 60
