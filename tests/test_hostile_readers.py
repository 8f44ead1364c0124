"""Issue 42, breaks 9-13 and 15-18: every reader bounded in memory, every number range-checked
before a cast, clock-track task files verified by --resume, ``fkopt check`` counting every answer,
the Python API's options bounded, and the suite-name, submission and ``instances:`` rules as
docs/kinbench.md states them. Each test reproduces its break (it failed before the fix)."""
import gzip
import hashlib
import json
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
import yaml

from fkopt.errors import FkoptError
from test_kinbench_v3 import fk_submission, submission, tiny_v3

ROOT = Path(__file__).resolve().parents[1]


def one_line(err) -> str:
    text = str(err.value)
    assert "\n" not in text and "Traceback" not in text
    return text


# -- break 9: CSV parsing bounded in memory, not only in bytes --------------------------------------
@pytest.mark.parametrize("data, fragment", [
    (b"," * (256 * 1024) + b"\n", "longer than the 65536 accepted"),              # the 256 KiB line
    (b",".join(b"c%d" % i for i in range(2000)) + b"\n", "header: 2000 fields, more than the 1024"),
    (b"a,b\n" + b"1," * 3000 + b"1\n", "line 2: 3001 fields"),
    (b'a,b\n"x\n' + b"y" * 10 + b'",2\n', "a quoted field spans lines"),
])
def test_a_csv_whose_parsing_would_take_gigabytes_is_one_line_before_pandas(tmp_path, data, fragment):
    from fkopt.files import read_csv
    path = tmp_path / "wide.csv"
    path.write_bytes(data)
    with pytest.raises(FkoptError) as err:
        read_csv(path, field="outside[0].file")
    assert fragment in one_line(err) and "wide.csv" in str(err.value)


def test_a_submission_of_one_long_line_of_commas_names_the_file(tmp_path):
    from fkopt.kinbench.submissions import read_submission
    cfg, arms = fk_submission(tmp_path, lambda m, g: pd.DataFrame({"robot": ["x"]}))
    (tmp_path / "tests" / "my-fk.csv").write_bytes(b"robot,query," + b"," * (300 * 1024) + b"\n")
    with pytest.raises(FkoptError) as err:
        read_submission(cfg, 0, arms)
    assert "my-fk.csv" in one_line(err) and "accepted in a CSV" in str(err.value)


def test_a_stored_csv_of_too_many_cells_is_refused(tmp_path, monkeypatch):
    import fkopt.files as files
    monkeypatch.setattr(files.csv_reading, "MAX_CSV_CELLS", 1000)     # the module that reads the bound
    (tmp_path / "runs.csv").write_text("a,b\n" + "1,2\n" * 600)
    with pytest.raises(FkoptError) as err:
        files.read_stored_csv(tmp_path, "runs.csv")
    assert "more than 1000 cells" in one_line(err)
    (tmp_path / "runs.csv").write_text("a,b\n" + "1,2\n" * 400)
    assert files.read_stored_csv(tmp_path, "runs.csv").shape == (400, 2)


def test_no_reader_of_fkopt_calls_pandas_read_csv_on_unchecked_bytes():
    """Every CSV goes through fkopt/files/csv_reading.py's bounded reader (check_csv_shape before pandas)."""
    callers = []
    for path in (ROOT / "fkopt").rglob("*.py"):
        if path.relative_to(ROOT).as_posix() == "fkopt/files/csv_reading.py":
            continue
        for n, line in enumerate(path.read_text().splitlines(), 1):
            if "pd.read_csv(" in line and "check_csv_shape" not in path.read_text():
                callers.append(f"{path.relative_to(ROOT)}:{n}")
    assert callers == []


# -- break 10: numbers range-checked before any cast -----------------------------------------------
def test_a_400_digit_query_in_a_submission_is_one_line(tmp_path):
    from fkopt.run.pipeline import load_any, run_config
    path = submission(tmp_path, lambda df: df.astype({"query": object}).assign(query=["9" * 400] + list(df["query"][1:])))
    with pytest.raises(FkoptError) as err:
        run_config(load_any(path), tmp_path / "out", source=str(path))
    assert "line 2: query = 999" in one_line(err) and "allowed: an integer 0..2" in str(err.value)


@pytest.mark.parametrize("column", ["pose", "evaluations"])
def test_a_400_digit_integer_in_an_outside_csv_is_one_line(tmp_path, column):
    from fkopt.kinbench.outside import logged_runs
    rows = pd.DataFrame([{"problem": "p", "set": "uniform", "pose": 0, "run": 0, "evaluations": 10,
                          "best_so_far": 1.0}] * 2).astype({column: object})
    rows.loc[1, column] = "7" * 400
    rows.to_csv(tmp_path / "log.csv", index=False)
    entry = SimpleNamespace(file="log.csv", ioh=None, algorithm=None)
    config = SimpleNamespace(outside=[entry])
    with pytest.raises(FkoptError) as err:
        list(logged_runs(config, 0, {("p", "uniform", 0)}, tmp_path))
    assert f"column '{column}' needs non-negative integers in [0, 2^53] (row 3)" in one_line(err)


def test_csv_numbers_never_raise():
    from fkopt.files import csv_numbers
    got = csv_numbers(pd.Series([10 ** 400, -(10 ** 400), "x", None, 3, "1" * 400]))
    assert got[0] == np.inf and got[1] == -np.inf and np.isnan(got[2:4]).all() and got[4] == 3 and got[5] == np.inf


# -- break 11: --resume verifies clock-track task files --------------------------------------------
@pytest.fixture(scope="module")
def clock_task(tmp_path_factory):
    """The tiny v3 suite's plan, one clock-track task and its finished record (computed here)."""
    from fkopt.kinbench.config import load_suite
    from fkopt.kinbench.runner import solve_task, suite_plan
    tmp = tmp_path_factory.mktemp("clock")
    path = tiny_v3(tmp)
    cfg = load_suite(path)
    plan = suite_plan(cfg, str(path), timing=False)
    task = next(t for t in plan.tasks if t.payload.get("track"))
    rec = json.loads(json.dumps(solve_task(task.payload)))       # as a task file holds it
    return plan, task, rec


def _forged(rec, edit):
    rec = json.loads(json.dumps(rec))
    a = rec["answers"]
    if edit == "joints-moved-90":            # verdicts kept: the file still says solved
        a["q0"] = [v + 90.0 for v in a["q0"]]
    elif edit == "solver-renamed":
        a["solver"] = ["tracik"] * len(a["solver"])
    elif edit == "robot-dropped":
        rec["answers"] = {k: [] for k in a}
    elif edit == "answer-dropped":
        rec["answers"] = {k: v[1:] for k, v in a.items()}
    elif edit == "answer-repeated":
        rec["answers"] = {k: [v[0]] + v[:-1] for k, v in a.items()}
    elif edit == "other-robot":
        a["robot"] = ["panda"] * len(a["robot"])
    elif edit == "answers-text":
        a["position_m"] = ["x"] * len(a["position_m"])
    elif edit == "answers-dict":
        a["q0"] = [{}] * len(a["q0"])
    elif edit == "column-missing":
        del a["seconds"]
    elif edit == "seconds-negative":
        a["seconds"][0] = -1.0
    elif edit == "answers-not-a-table":
        rec["answers"] = [1, 2]
    elif edit == "problem-text":
        rec["problem"] = "0"
    elif edit == "throughput-text":
        rec["throughput"]["queries_per_s"][0] = "fast"
    elif edit == "throughput-other-solver":
        rec["throughput"]["solver"][0] = "tracik"
    return rec


FORGERIES = ["joints-moved-90", "solver-renamed", "robot-dropped", "answer-dropped", "answer-repeated", "other-robot",
             "answers-text", "answers-dict", "column-missing", "seconds-negative", "answers-not-a-table",
             "problem-text", "throughput-text", "throughput-other-solver"]


def test_a_finished_clock_task_file_is_reused(clock_task):
    plan, task, rec = clock_task
    assert plan.check(task, rec) is None


@pytest.mark.parametrize("edit", FORGERIES)
def test_resume_refuses_a_forged_clock_task_file_with_a_re_signed_digest(clock_task, tmp_path, edit):
    from fkopt.run.tasks import TaskStore
    plan, task, rec = clock_task
    assert plan.check(task, _forged(rec, edit))            # the record check names why
    out = tmp_path / "out"
    store = TaskStore(out, out / "kinbench" / ".t.partial", out / "kinbench" / "t", "t", {}, plan.fingerprint)
    store.open(plan, resume=False)
    store.add(task.id, _forged(rec, edit))                 # written through fkopt: the digest is re-signed
    with pytest.raises(FkoptError) as err:
        TaskStore(out, out / "kinbench" / ".t.partial", out / "kinbench" / "t", "t", {},
                  plan.fingerprint).open(plan, resume=True)
    assert f"{task.id}.json: not a finished task of this run" in one_line(err)


# -- breaks 12, 13: fkopt check counts every answer, reads them bounded ----------------------------
@pytest.fixture(scope="module")
def stored_board(tmp_path_factory):
    from fkopt.run.pipeline import load_any, run_config
    from fkopt.kinbench.config import load_suite
    tmp = tmp_path_factory.mktemp("board")
    path = tiny_v3(tmp)
    folder = run_config(load_any(path), tmp / "out", source=str(path)).folder
    return folder, load_suite(path)


def _board_again(folder, cfg, answers):
    """Write ``answers`` and the board that follows from them, as a forger would."""
    from fkopt.kinbench.reports import robots_board_table
    answers.to_csv(folder / "answers.csv.gz", index=False, float_format="%.17g")
    tp = pd.read_csv(folder / "throughput.csv")
    board = robots_board_table(SimpleNamespace(config=cfg, answers=answers, throughput=tp))
    if board is not None:
        board.to_csv(folder / "leaderboard-robots.csv", index=False)


@pytest.mark.parametrize("tamper", ["failures-deleted", "duplicates", "solver-dropped", "robot-dropped", "extra-answer",
                                    "emptied", "zero-bytes", "deleted", "not-gzip", "query-400-digits"])
def test_check_fails_a_board_whose_answers_are_missing_duplicated_extra_or_unreadable(stored_board, tmp_path,
                                                                                      tamper):
    import shutil
    from fkopt.kinbench.verify import reverify
    src, cfg = stored_board
    folder = tmp_path / "copy"
    shutil.copytree(src, folder)
    assert reverify(folder, cfg) == []
    answers = pd.read_csv(folder / "answers.csv.gz")
    if tamper == "failures-deleted":               # the 'worst' answers taken away
        _board_again(folder, cfg, answers.drop(index=answers["position_m"].idxmax()))
    elif tamper == "duplicates":                   # one answer replaced by a copy of another
        _board_again(folder, cfg, pd.concat([answers.iloc[1:2], answers.iloc[1:]], ignore_index=True))
    elif tamper == "solver-dropped":
        _board_again(folder, cfg, answers[~((answers.robot == "panda") & (answers.solver == "fkopt.inverse"))])
    elif tamper == "robot-dropped":
        _board_again(folder, cfg, answers[answers.robot != "panda"])
    elif tamper == "extra-answer":
        _board_again(folder, cfg, pd.concat([answers, answers.iloc[:1].assign(query=3)], ignore_index=True))
    elif tamper == "emptied":
        _board_again(folder, cfg, answers.iloc[:0])
    elif tamper == "zero-bytes":
        (folder / "answers.csv.gz").write_bytes(gzip.compress(b""))
    elif tamper == "deleted":
        (folder / "answers.csv.gz").unlink()
    elif tamper == "not-gzip":
        (folder / "answers.csv.gz").write_bytes(b"robot,query\nur5,0\n")
    elif tamper == "query-400-digits":
        text = gzip.decompress((folder / "answers.csv.gz").read_bytes()).decode()
        head, first, rest = text.split("\n", 2)
        (folder / "answers.csv.gz").write_bytes(gzip.compress(
            "\n".join([head, first.replace("ur5,uniform,0,", "ur5,uniform," + "9" * 400 + ",", 1), rest]).encode()))
    bad = reverify(folder, cfg)
    assert bad and bad[0][0] == "answers.csv.gz", bad
    assert all("\n" not in str(part) for row in bad for part in row)
    if tamper == "not-gzip":
        assert "answers.csv.gz: not a valid gzip file" in str(bad[0][3])


def test_fkopt_check_of_a_board_whose_answers_are_not_gzip_names_the_file_and_exits_1(stored_board, tmp_path):
    import shutil
    src, _ = stored_board
    folder = tmp_path / "copy"
    shutil.copytree(src, folder)
    (folder / "answers.csv.gz").write_bytes(b"robot,query\nur5,0\n")
    r = subprocess.run([sys.executable, "-m", "fkopt.cli", "check", str(folder)], capture_output=True, text=True,
                       env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    assert r.returncode == 1, r.stderr
    text = r.stdout + r.stderr
    assert "answers.csv.gz: not a valid gzip file" in text and "Traceback" not in text


# -- break 15: the Python API ----------------------------------------------------------------------
@pytest.fixture(scope="module")
def arm():
    import fkopt
    return fkopt.mechanism("7dof-arm")


def _api_calls(arm):
    import fkopt
    T = arm.fk_matrix(np.full(arm.dof, 10.0))
    return {
        "empty-batch": (lambda: fkopt.inverse(arm, np.zeros((0, 4, 4))), "no values (an empty batch"),
        "seed-2**64": (lambda: fkopt.inverse(arm, T, seed=2 ** 64), "seed: expected an integer >= 0 and <= 9223372036854775807"),
        "solver-seed-2**64": (lambda: fkopt.InverseSolver(arm)(T, seed=2 ** 64), "seed: expected an integer"),
        "restarts-10**30": (lambda: fkopt.inverse(arm, T, restarts=10 ** 30), "restarts: expected an integer >= 0 and <= 1000000"),
        "table-10**30": (lambda: fkopt.inverse(arm, T, table=10 ** 30), "table: expected an integer >= 0 and <= 1000000"),
        "table-10**7": (lambda: fkopt.inverse_solver(arm, table=10 ** 7), "table: expected an integer >= 0 and <= 1000000"),
        "solver-None": (lambda: fkopt.InverseSolver(None), "expected a registered mechanism name or a mechanism object"),
        "forward-start-1e300": (lambda: fkopt.forward("6-sps", [1000.0] * 6, start=[1e300] * 6),
                                "start: values must be finite and within +-1e+09"),
        "forward-table-x": (lambda: fkopt.forward("6-sps", [1000.0] * 6, table="x"), "forward table: expected an integer"),
        "forward-seed-2**64": (lambda: fkopt.forward("6-sps", [1000.0] * 6, seed=2 ** 64), "forward seed"),
        "complex-frame": (lambda: fkopt.inverse(arm, T.astype(complex)), "complex numbers are not accepted"),
        "complex-pose": (lambda: fkopt.inverse(arm, arm.fk(np.full(arm.dof, 10.0)) + 1j), "complex numbers"),
        "angles-1e300": (lambda: fkopt.inverse(arm, [0.1, 0.1, 0.1, 1e300, 0.0, 0.0]),
                         "values must be finite and within +-1e+09"),
        "damping-1e300": (lambda: fkopt.inverse(arm, T, damping=1e300), "damping: expected a number > 0 and <= 1e+09"),
        "tol-1e300": (lambda: fkopt.inverse(arm, T, tol=(1e300, 1e-6)), "tolerances must be positive and at most 1e+09"),
    }


@pytest.mark.parametrize("case", list(_api_calls(SimpleNamespace(fk_matrix=lambda q: np.eye(4), dof=7,
                                                                   fk=lambda q: np.zeros(6)))))
def test_every_api_entry_raises_one_fkopt_error_line_for_bad_input(arm, case):
    call, fragment = _api_calls(arm)[case]
    with pytest.raises(FkoptError) as err:
        call()
    assert fragment in one_line(err)


def test_the_api_bounds_leave_good_calls_alone(arm):
    import fkopt
    T = arm.fk_matrix(np.full(arm.dof, 10.0))
    assert fkopt.inverse(arm, T, seed=2 ** 63 - 1, table=1024).solved
    assert fkopt.inverse(arm, np.stack([T, T])).solved.all()


# -- break 16: a 64-character suite name and --quick -----------------------------------------------
def test_a_suite_name_too_long_for_its_quick_result_is_refused_not_cut(tmp_path):
    from fkopt.kinbench.config import MAX_QUICK_NAME, load_suite
    path = tiny_v3(tmp_path)
    data = yaml.safe_load(path.read_text())
    data["name"] = "n" * 64
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(FkoptError) as err:
        load_suite(path)
    assert f"a suite with a quick: block takes at most {MAX_QUICK_NAME}" in one_line(err)
    data["name"] = "n" * MAX_QUICK_NAME
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    quick = load_suite(path).quick_tier()
    assert quick.name == "n" * MAX_QUICK_NAME + "-quick" and len(quick.name) == 64


# -- break 17: submissions as docs/kinbench.md describes them --------------------------------------
def test_a_stray_column_in_a_submission_is_refused(tmp_path):
    from fkopt.run.pipeline import load_any, run_config
    path = submission(tmp_path, lambda df: df.assign(given_timeout=5))      # a typo of given_timeout_ms
    with pytest.raises(FkoptError) as err:
        run_config(load_any(path), tmp_path / "out", source=str(path))
    assert "stray column 'given_timeout'; allowed: robot, query" in one_line(err)


def test_given_timeout_ms_takes_every_timeout_the_track_allows(tmp_path):
    from fkopt.kinbench.config import load_suite
    from fkopt.kinbench.posesets import load_pose_sets
    from fkopt.kinbench.runner import read_submissions, track_cases
    path = submission(tmp_path, lambda df: pd.concat([df.assign(given_timeout_ms=t) for t in (20, 5000)]))
    data = yaml.safe_load(path.read_text())
    data["tracks"]["clock"]["timeouts_ms"] = [20, 5000]                      # tracks allow up to 10,000 ms
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    cfg = load_suite(path)
    sets, _ = load_pose_sets(cfg)
    got = read_submissions(cfg, track_cases(cfg, sets))
    assert set(got["given_timeout_ms"]) == {20.0, 5000.0}


def test_more_clock_queries_than_the_set_holds_is_refused(tmp_path):
    from fkopt.kinbench.config import load_suite
    from fkopt.kinbench.posesets import load_pose_sets
    from fkopt.kinbench.runner import track_cases
    cfg = load_suite(tiny_v3(tmp_path, queries=200))
    sets, _ = load_pose_sets(cfg)
    with pytest.raises(FkoptError) as err:
        track_cases(cfg, sets)
    assert "tracks.clock.queries: 200, but set 'uniform' of problem ur5 holds 20 poses" in one_line(err)


@pytest.mark.parametrize("clock, field", [({"fk_solvers": ["fkopt.forward", "fkopt.forward"]}, "fk_solvers"),
                                          ({"solvers": ["fkopt.inverse", "fkopt.inverse"]}, "solvers")])
def test_repeated_solvers_and_fk_solvers_are_both_refused(tmp_path, clock, field):
    from fkopt.kinbench.config import load_suite
    with pytest.raises(FkoptError) as err:
        load_suite(tiny_v3(tmp_path, **clock))
    assert f"{field}: 'fkopt." in one_line(err) and "must not repeat" in str(err.value)


# -- break 18: instances: bounded before any geometry is drawn ------------------------------------
def test_instances_are_counted_before_any_is_drawn(tmp_path, monkeypatch):
    import fkopt.kinbench.instances as instances
    from fkopt.kinbench.config import suite_from_dict
    monkeypatch.setattr(instances, "expand", lambda *a, **k: pytest.fail("a geometry was drawn"))
    problem = {"problem_class": "parallel-fk-6dof", "instances": 100, "mechanism": {"name": "6-sps"}}
    data = {"kind": "suite", "name": "big", "pose_sets": "none", "solvers": [{"name": "lm"}],
            "problems": [{**problem, "name": f"p{k}"} for k in range(40)]}
    with pytest.raises(FkoptError) as err:
        suite_from_dict(data, "big.yaml")
    assert "4000 geometry instances in all; allowed: at most 100 per suite" in one_line(err)


def test_digests_of_forged_task_files_are_what_the_store_recorded(clock_task, tmp_path):
    """The forgeries above pass the digest check (fkopt re-signed them): only the record check stops them."""
    from fkopt.run.tasks import TaskStore, read_manifest
    plan, task, rec = clock_task
    out = tmp_path / "out"
    store = TaskStore(out, out / "k" / ".t.partial", out / "k" / "t", "t", {}, plan.fingerprint)
    store.open(plan, resume=False)
    store.add(task.id, _forged(rec, "joints-moved-90"))
    data = (out / "k" / ".t.partial" / "tasks" / f"{task.id}.json").read_bytes()
    assert read_manifest(out / "k" / ".t.partial" / "tasks")["tasks"][task.id] == hashlib.sha256(data).hexdigest()
