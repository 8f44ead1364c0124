"""One result for every kind (issue 39): every merge returns a RunResult, every worker's record is
JSON (a task file), and experiments keep task files and resume like studies and suites."""
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

import fkopt.kinbench  # noqa: F401 (registers every kind)
from fkopt.errors import FkoptError
from fkopt.run.pipeline import from_dict, plan_config, run_config, run_in_memory
from fkopt.run.result import RunResult, dataclass_from_json, dataclass_to_json, from_json, to_json
from fkopt.run.tasks import TASKS, run_tasks
from fkopt.solve import Result
from conftest import interrupted_after_first_task, wait_while_running

ROOT = Path(__file__).resolve().parents[1]
EXPERIMENT = {"name": "two", "paper": "test", "mechanism": {"name": "3-rps"}, "seed": 3,
              "cases": [{"pose": {"alpha": 9, "beta": 13, "z": 622}}, {"pose": {"alpha": -5, "beta": 4, "z": 640}}],
              "algorithms": [{"name": "gabc"}, {"name": "pso"}, {"name": "abc", "label": "a"}],
              "population": 8, "iterations": 20, "runs": 3, "threshold": 1e-6}
STUDY = {"kind": "study", "name": "st", "mechanism": {"name": "3-rps"}, "poses": {"uniform": 4, "seed": 1},
         "algorithms": [{"name": "gabc"}], "population": 6, "iterations": 8, "runs": 2, "seed": 1, "chunk": 2}
ASSEMBLY = {"kind": "assembly", "name": "asm", "mechanism": {"name": "3-rps"},
            "joints": {"d1": 598.85, "d2": 671.92, "d3": 629.16}, "population": 50, "iterations": 20}
DETERMINISTIC = ("summary.csv", "values.csv", "runs.csv", "trace.csv.gz", "convergence.csv")


def test_json_round_trip_is_bit_exact():
    value = {"a": np.array([[1.5, np.nan], [np.inf, -0.0]]), 3: np.arange(4, dtype=np.float32) / 3,
             "t": (np.array([1, 2], dtype=np.int64), "x"), "n": None, "s": np.float64(0.1) * 3}
    back = from_json(json.loads(json.dumps(to_json(value))))
    assert set(back) == {"a", 3, "t", "n", "s"}          # an int key stays an int
    np.testing.assert_array_equal(back["a"], value["a"])
    assert np.signbit(back["a"][1, 1])                   # -0.0 kept
    assert back[3].dtype == np.float32 and back[3].tobytes() == value[3].tobytes()
    assert back["t"][0].dtype == np.int64 and back["t"][1] == "x" and back["s"] == value["s"]


def test_every_kind_merges_into_a_run_result():
    for data in (EXPERIMENT, STUDY, ASSEMBLY):
        result = run_in_memory(from_dict(data, "t"), timing=False)
        assert isinstance(result, RunResult) and result.own is not None, data["name"]
        assert result.timing is not None
    exp = run_in_memory(from_dict(EXPERIMENT, "t"), timing=False)
    assert len(exp.record) == 2 * 3 * 3 and list(exp.record["pose"].unique()) == [0, 1]
    assert list(exp.trace.columns) == ["case", "algorithm", "run", "iteration", "evaluations", "best_fitness"]


def test_experiment_task_records_are_json_and_give_the_same_result():
    """A worker's record goes through JSON (a task file) and back without moving a number: the
    curves it carries rebuild the solver's Result bit for bit."""
    config = from_dict(EXPERIMENT, "t")
    plan = plan_config(config, timing=False)
    rec = plan.local(plan.tasks[0].payload)
    again = json.loads(json.dumps(rec))
    a, b = dataclass_from_json(Result, rec["curves"]), dataclass_from_json(Result, again["curves"])
    for name in ("fitness", "history", "evaluation_history", "x", "iterations_done"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes(), name
    assert plan.check(plan.tasks[0], again) is None
    assert dataclass_to_json(b) == rec["curves"]


def test_experiment_record_checks_refuse_a_foreign_record():
    config = from_dict(EXPERIMENT, "t")
    plan = plan_config(config, timing=False)
    rec = json.loads(json.dumps(plan.local(plan.tasks[0].payload)))
    assert "algorithm" in plan.check(plan.tasks[1], rec)
    rec["rows"][0]["run"] = [0, 0, 0]
    assert "runs are not this task's" in plan.check(plan.tasks[0], rec)
    assert "not a task record" in plan.check(plan.tasks[0], [1])


def _folder_bytes(folder: Path) -> dict:
    return {name: (folder / name).read_bytes() for name in DETERMINISTIC}


def test_experiment_resume_reuses_its_task_files(tmp_path):
    """An experiment stopped after its first task keeps that task file (with its digest);
    resume=True computes only the others and writes what an uninterrupted run writes."""
    config = from_dict(EXPERIMENT, "t")
    whole = run_config(config, tmp_path / "whole")
    interrupted_after_first_task(config, tmp_path / "out")
    tasks = tmp_path / "out" / "test" / ".two.partial" / TASKS
    assert sorted(p.name for p in tasks.iterdir()) == ["a00.json", "manifest.json"]
    assert not (tmp_path / "out" / "test" / "two").exists()
    again = run_config(config, tmp_path / "out", resume=True)
    assert sorted(again.computed) == ["a01", "a02", "t00", "t01"]          # the solves left and the timing
    assert _folder_bytes(again.folder) == _folder_bytes(whole.folder)
    assert not (tmp_path / "out" / "test" / ".two.partial").exists()
    assert not (again.folder / TASKS).exists()          # an experiment's folder keeps no task files


def test_experiment_resume_refuses_a_changed_task_file(tmp_path):
    config = from_dict(EXPERIMENT, "t")
    interrupted_after_first_task(config, tmp_path)
    path = tmp_path / "test" / ".two.partial" / TASKS / "a00.json"
    path.write_text(path.read_text().replace('"solver":"gabc"', '"solver":"gabc" '))
    with pytest.raises(FkoptError, match="changed since fkopt wrote it"):
        run_config(config, tmp_path, resume=True)


def test_ctrl_c_of_an_experiment_keeps_its_tasks_and_resume_finishes_it(tmp_path):
    """A real SIGINT to the process group of ``fkopt run`` once the first algorithm's task file
    is on disk: the file stays with its digest, ``fkopt run --resume`` computes only the rest, and
    the deterministic files are byte for byte those of an uninterrupted run."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    slow = {**EXPERIMENT, "name": "cut", "cases": EXPERIMENT["cases"][:1],
            "algorithms": [{"name": "pso", "iterations": 20}, {"name": "abc", "iterations": 1500}],
            "population": 40, "runs": 30}
    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml.safe_dump(slow, sort_keys=False))
    run = [sys.executable, "-m", "fkopt.cli", "run", str(cfg), "-q"]
    out = tmp_path / "out"
    manifest = out / "test" / ".cut.partial" / TASKS / "manifest.json"
    p = subprocess.Popen([*run, "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True, env=env)
    wait_while_running(p, lambda: (manifest.parent / "a00.json").exists()        # the first task on disk
                       and "a00" in json.loads(manifest.read_text())["tasks"], 240)
    assert p.poll() is None, "the run finished before it could be interrupted; make abc slower"
    os.killpg(p.pid, signal.SIGINT)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err[-500:]
    assert f"the finished tasks of this experiment are kept: fkopt run {cfg} --out {out} --resume continues" in err
    assert not (out / "test" / "cut").exists()
    assert sorted(json.loads(manifest.read_text())["tasks"]) == ["a00"]
    proc = subprocess.run([*run[:-1], "--out", str(out), "--resume"], capture_output=True, text=True, timeout=600,
                          env=env)
    assert proc.returncode == 0, proc.stderr
    assert "resumed: 1 finished task(s) reused, 2 computed" in proc.stdout     # abc's solve and the timing task
    assert not manifest.parent.parent.exists()
    whole = subprocess.run([*run, "--out", str(tmp_path / "whole")], capture_output=True, text=True, timeout=600,
                           env=env)
    assert whole.returncode == 0, whole.stderr
    for name in DETERMINISTIC:
        assert (out / "test" / "cut" / name).read_bytes() == (tmp_path / "whole" / "test" / "cut" / name
                                                              ).read_bytes(), name


def test_run_tasks_hands_the_same_records_to_a_worker_process():
    """Records are plain JSON wherever a task ran: a worker process's equal this process's."""
    config = from_dict(EXPERIMENT, "t")
    plan = plan_config(config, timing=False)
    here = run_tasks(plan)
    there = run_tasks(plan, jobs=2)
    for t in plan.tasks:
        a, b = dict(here.records[t.id]), dict(there.records[t.id])
        a.pop("wall_s"), b.pop("wall_s")
        a["curves"].pop("time_per_run"), b["curves"].pop("time_per_run")
        assert json.dumps(a) == json.dumps(b), t.id


def test_answers_use_the_record_names_and_old_answers_ask_for_a_re_store(tmp_path):
    """The clock track's answers.csv.gz says problem and pose (the run record's names); a board
    stored before the rename fails fkopt check with one line naming the old columns."""
    import shutil

    import pandas as pd

    from fkopt.kinbench.answer_checks import ANSWER_COLUMNS as checked
    from fkopt.kinbench.clock import ANSWER_COLUMNS
    from fkopt.kinbench.verify import reverify
    from fkopt.run.pipeline import load_any
    assert checked is ANSWER_COLUMNS and ANSWER_COLUMNS[:3] == ("problem", "set", "pose")
    quick = ROOT / "results" / "kinbench" / "kinbench-v3-robots-quick"
    stored = pd.read_csv(quick / "answers.csv.gz")
    assert list(stored.columns[:len(ANSWER_COLUMNS)]) == list(ANSWER_COLUMNS)
    folder = tmp_path / "board"
    shutil.copytree(quick, folder)
    stored.rename(columns={"problem": "robot", "pose": "query"}).to_csv(
        folder / "answers.csv.gz", index=False, float_format="%.17g")
    config = load_any(ROOT / "configs" / "suites" / "kinbench-v3-robots.yaml").quick_tier()
    rows = reverify(folder, config)
    assert len(rows) == 1 and rows[0][2] == "columns" and rows[0][3] == "robot, query"
    assert "re-store this board" in rows[0][5]
