"""Hostile and faulty input (issue 10): every one gets exit 2 and exactly one line on stderr, and
nothing is written anywhere -- previous results stay byte-identical, nothing appears outside the
out folder. Interrupted reruns (SIGINT to the process group, kill -9) keep the previous result.

The corpus runs in this process (``fkopt.cli.main`` with argv), so it stays fast; the interrupt
tests need real processes.
"""
import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml
from conftest import wait_while_running


BASE = {
    "name": "fresh", "paper": "test", "title": "hostile base",
    "mechanism": {"name": "3-rps"},
    "cases": [{"pose": {"alpha": 9, "beta": 13, "z": 622}}],
    "algorithms": [{"name": "gabc"}],
    "population": 4, "iterations": 5, "runs": 2, "seed": 1,
}
STUDY = {
    "kind": "study", "name": "fresh", "mechanism": {"name": "3-rps"}, "poses": {"uniform": 2, "seed": 1},
    "algorithms": [{"name": "gabc"}], "population": 4, "iterations": 5, "runs": 2, "seed": 1,
}
ASSEMBLY = {"kind": "assembly", "name": "fresh", "mechanism": {"name": "3-rps"},
            "joints": {"d1": 598.85, "d2": 671.92, "d3": 629.16}, "population": 50, "iterations": 20}


def yaml_of(data) -> str:
    return yaml.safe_dump(data, sort_keys=False)


def with_(base, **change):
    data = {**base, **change}
    return yaml_of({k: v for k, v in data.items() if v is not DROP})


DROP = object()
BOMB = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
    for p, c in zip("abcdefgh", "bcdefghi")) + "printed: *i\n"

#: (id, file contents (text or bytes) or None, argv template) -- ``{f}`` is the file, ``{out}``
#: the results root, ``{root}`` the sandbox. Expected: exit 2, one line, fragments in it.
CORPUS = [
    # -- paper / name: single safe path components ------------------------------------------------
    ("name-dotdot", with_(BASE, name=".."), ["run", "{f}", "--out", "{out}"], ["name", "single safe folder name"]),
    ("name-dot", with_(BASE, name="."), ["run", "{f}", "--out", "{out}"], ["name"]),
    ("name-slash", with_(BASE, name="a/b"), ["run", "{f}", "--out", "{out}"], ["name"]),
    ("name-absolute", with_(BASE, name="/etc"), ["run", "{f}", "--out", "{out}"], ["name"]),
    ("name-5000", with_(BASE, name="x" * 5000), ["run", "{f}", "--out", "{out}"], ["name", "at most 64"]),
    ("name-empty", with_(BASE, name=""), ["run", "{f}", "--out", "{out}"], ["name"]),
    ("name-hidden", with_(BASE, name=".hidden"), ["run", "{f}", "--out", "{out}"], ["name"]),
    ("name-number", with_(BASE, name=123), ["run", "{f}", "--out", "{out}"], ["name"]),
    ("name-newline", with_(BASE, name="a\nb"), ["run", "{f}", "--out", "{out}"], ["name"]),
    ("paper-dotdot", with_(BASE, paper="..", name="configs"), ["run", "{f}", "--out", "{out}"], ["paper"]),
    ("paper-absolute", with_(BASE, paper="/tmp", name="important"), ["run", "{f}", "--out", "{out}"], ["paper"]),
    ("paper-traversal", with_(BASE, paper="a/../.."), ["run", "{f}", "--out", "{out}"], ["paper"]),
    ("paper-backslash", with_(BASE, paper="a\\b"), ["run", "{f}", "--out", "{out}"], ["paper"]),
    ("study-name-dotdot", with_(STUDY, name=".."), ["study", "{f}", "--out", "{out}"], ["name"]),
    ("study-paper-absolute", with_(STUDY, paper="/tmp"), ["study", "{f}", "--out", "{out}"], ["paper"]),
    ("assembly-name-dotdot", with_(ASSEMBLY, name=".."), ["run", "{f}", "--out", "{out}"], ["name"]),
    ("assembly-paper-absolute", with_(ASSEMBLY, paper="/tmp"), ["run", "{f}", "--out", "{out}"], ["paper"]),
    # -- numbers and limits -------------------------------------------------------------------------
    ("seed-negative", with_(BASE, seed=-1), ["run", "{f}", "--out", "{out}"], ["seed", "greater than or equal to 0"]),
    ("seed-huge", with_(BASE, seed=2**70), ["run", "{f}", "--out", "{out}"], ["seed"]),
    ("random-seed-negative", with_(BASE, cases={"random": 2, "seed": -5}), ["run", "{f}", "--out", "{out}"], ["seed"]),
    ("cases-empty", with_(BASE, cases=[]), ["run", "{f}", "--out", "{out}"], ["cases", "1 to"]),
    ("cases-random-zero", with_(BASE, cases={"random": 0}), ["run", "{f}", "--out", "{out}"], ["random"]),
    ("cases-random-1e9", with_(BASE, cases={"random": 10**9}), ["run", "{f}", "--out", "{out}"], ["random", "less than or equal"]),
    ("runs-1e9", with_(BASE, runs=10**9), ["run", "{f}", "--out", "{out}"], ["runs", "less than or equal"]),
    ("population-1e9", with_(BASE, population=10**9), ["run", "{f}", "--out", "{out}"], ["population"]),
    ("iterations-1e9", with_(BASE, iterations=10**9), ["run", "{f}", "--out", "{out}"], ["iterations"]),
    ("memory-estimate", with_(BASE, runs=100_000, population=100_000, iterations=1_000_000),
     ["run", "{f}", "--out", "{out}"], ["GiB of memory"]),
    ("threshold-nan", with_(BASE, threshold=float("nan")), ["run", "{f}", "--out", "{out}"], ["not a finite number"]),
    ("threshold-inf", with_(BASE, threshold=float("inf")), ["run", "{f}", "--out", "{out}"], ["not a finite number"]),
    ("threshold-overflow", with_(BASE).replace("seed: 1", "seed: 1\nthreshold: 1e400"), ["run", "{f}", "--out", "{out}"],
     ["threshold", "finite"]),
    ("threshold-text-nan", with_(BASE, threshold="nan"), ["run", "{f}", "--out", "{out}"], ["threshold", "finite"]),
    ("pose-nan", with_(BASE, cases=[{"pose": {"alpha": float("nan"), "beta": 0, "z": 600}}]),
     ["run", "{f}", "--out", "{out}"], ["not a finite number"]),
    ("population-text", with_(BASE, population="many"), ["run", "{f}", "--out", "{out}"], ["population"]),
    ("study-uniform-1e9", with_(STUDY, poses={"uniform": 10**9}), ["study", "{f}", "--out", "{out}"], ["poses"]),
    ("study-seed-negative", with_(STUDY, seed=-1), ["study", "{f}", "--out", "{out}"], ["seed"]),
    ("study-grid-huge", with_(STUDY, poses={"grid": {"alpha": [-1, 1, 1000], "beta": [-1, 1, 1000]},
                                            "fixed": {"z": 550}}), ["study", "{f}", "--out", "{out}"], ["grid"]),
    ("study-label-5000", with_(STUDY, algorithms=[{"name": "gabc", "label": "l" * 5000}]),
     ["study", "{f}", "--out", "{out}"], ["label"]),
    ("study-runs-1e9", with_(STUDY, runs=10**9), ["study", "{f}", "--out", "{out}"], ["runs"]),
    # -- YAML itself --------------------------------------------------------------------------------
    ("yaml-duplicate-key", yaml_of(BASE) + "runs: 3\n", ["run", "{f}", "--out", "{out}"], ["duplicate key 'runs'"]),
    ("yaml-alias-bomb", yaml_of(BASE) + BOMB, ["run", "{f}", "--out", "{out}"], ["anchors and aliases"]),
    ("yaml-anchor", yaml_of(BASE).replace("population: 4", "population: &p 4\nruns2: *p"),
     ["run", "{f}", "--out", "{out}"], ["anchors and aliases"]),
    ("yaml-not-utf8", b"name: \xff\xfe\n", ["run", "{f}", "--out", "{out}"], ["not UTF-8"]),
    ("yaml-latin1", yaml_of(BASE).replace("hostile base", "caf\u00e9").encode("latin-1"),
     ["run", "{f}", "--out", "{out}"], ["not UTF-8"]),
    ("yaml-too-large", yaml_of(BASE) + "#" * (1 << 20) + "\n", ["run", "{f}", "--out", "{out}"], ["larger than"]),
    ("yaml-deep", "a: " + "[" * 5000 + "]" * 5000 + "\n", ["run", "{f}", "--out", "{out}"], ["nested"]),
    ("yaml-list", "- 1\n- 2\n", ["run", "{f}", "--out", "{out}"], ["expected a mapping"]),
    ("yaml-empty", "", ["run", "{f}", "--out", "{out}"], ["expected a mapping"]),
    ("yaml-scalar", "hello\n", ["run", "{f}", "--out", "{out}"], ["expected a mapping"]),
    ("yaml-python-tag", "name: !!python/object/apply:os.system ['touch pwned']\n", ["run", "{f}", "--out", "{out}"],
     ["malformed YAML"]),
    ("yaml-malformed", "name: x\nmechanism: {name: 3-rps\n", ["run", "{f}", "--out", "{out}"], ["malformed YAML at line"]),
    ("yaml-int-key", "1: 2\n", ["run", "{f}", "--out", "{out}"], ["field names must be text"]),
    ("yaml-control-chars", with_(BASE, title="x", colour="\x1b[31mred\x07"), ["run", "{f}", "--out", "{out}"],
     ["unknown field"]),
    # -- schema --------------------------------------------------------------------------------------
    ("unknown-field", with_(BASE, colour=1), ["run", "{f}", "--out", "{out}"], ["colour", "unknown field"]),
    ("kind-unknown", with_(BASE, kind="survey"), ["run", "{f}", "--out", "{out}"], ["kind: 'survey' unknown"]),
    ("kind-not-text", with_(BASE, kind=[1]), ["run", "{f}", "--out", "{out}"], ["kind"]),
    ("mechanism-unknown", with_(BASE, mechanism={"name": "4-rps"}), ["run", "{f}", "--out", "{out}"], ["unknown mechanism"]),
    ("bounds-reversed", with_(BASE, mechanism={"name": "3-rps", "bounds": {"z": [700, 400]}}),
     ["run", "{f}", "--out", "{out}"], ["bounds.z"]),
    ("pose-outside", with_(BASE, cases=[{"pose": {"alpha": 9, "beta": 13, "z": 5000}}]),
     ["run", "{f}", "--out", "{out}"], ["z=5000"]),
    ("algorithm-unknown", with_(BASE, algorithms=[{"name": "bee"}]), ["run", "{f}", "--out", "{out}"], ["unknown algorithm"]),
    ("algorithm-param", with_(BASE, algorithms=[{"name": "abc", "params": {"limit": -1}}]),
     ["run", "{f}", "--out", "{out}"], ["limit"]),
    ("algorithm-duplicate", with_(BASE, algorithms=[{"name": "abc"}, {"name": "abc"}]),
     ["run", "{f}", "--out", "{out}"], ["unique"]),
    ("algorithms-empty", with_(BASE, algorithms=[]), ["run", "{f}", "--out", "{out}"], ["algorithms"]),
    ("stop-without-threshold", with_(BASE, stop_at_threshold=True), ["run", "{f}", "--out", "{out}"], ["threshold"]),
    ("study-via-run-jobs-0", yaml_of(STUDY), ["run", "{f}", "--out", "{out}", "--jobs", "0"], ["--jobs"]),
    ("experiment-via-study", yaml_of(BASE), ["study", "{f}", "--out", "{out}"], ["not a study file", "fkopt run"]),
    ("assembly-serial", with_(ASSEMBLY, mechanism={"name": "7dof-arm"}), ["run", "{f}", "--out", "{out}"], ["parallel"]),
    # -- geometry files and CLI arguments -------------------------------------------------------------
    ("geometry-not-utf8", b"ra: \xff\n", ["ik", "3-rps", "--pose", "alpha=0,beta=0,z=600", "--geometry", "{f}"],
     ["not UTF-8"]),
    ("geometry-duplicate", "ra: 1\nra: 2\n", ["ik", "3-rps", "--pose", "alpha=0,beta=0,z=600", "--geometry", "{f}"],
     ["duplicate key 'ra'"]),
    ("geometry-list", "- 1\n", ["ik", "3-rps", "--pose", "alpha=0,beta=0,z=600", "--geometry", "{f}"],
     ["expected a mapping"]),
    ("geometry-bomb", BOMB, ["ik", "3-rps", "--pose", "alpha=0,beta=0,z=600", "--geometry", "{f}"], ["anchors and aliases"]),
    ("geometry-inf", "ra: .inf\n", ["ik", "3-rps", "--pose", "alpha=0,beta=0,z=600", "--geometry", "{f}"],
     ["not a finite number"]),
    # 1e400 is a number (YAML 1.2's float without a dot, as fkopt reads YAML): its field and line named
    ("geometry-overflow-text", "ra: 1e400\n", ["ik", "3-rps", "--pose", "alpha=0,beta=0,z=600", "--geometry", "{f}"],
     ["ra: '1e400'", "not a finite number"]),
    ("geometry-overflow", "ra: 1.0e+400\n", ["ik", "3-rps", "--pose", "alpha=0,beta=0,z=600", "--geometry", "{f}"],
     ["not a finite number"]),
    ("geometry-missing", None, ["ik", "3-rps", "--pose", "alpha=0,beta=0,z=600", "--geometry", "{root}/nope.yaml"],
     ["cannot read"]),
    ("fk-seed-negative", None, ["fk", "3-rps", "--joints", "d1=598.85,d2=671.92,d3=629.16", "--seed", "-1"], ["--seed"]),
    ("ik-nan", None, ["ik", "3-rps", "--pose", "alpha=nan,beta=0,z=600"], ["finite"]),
    ("ik-inf", None, ["ik", "3-rps", "--pose", "alpha=0,beta=0,z=inf"], ["finite"]),
    ("ik-duplicate", None, ["ik", "3-rps", "--pose", "alpha=1,alpha=2,beta=0,z=600"], ["'alpha' is given twice"]),
    ("fk-duplicate", None, ["fk", "3-rps", "--joints", "d1=1,d1=2,d2=3,d3=4"], ["'d1' is given twice"]),
    ("fk-empty-name", None, ["fk", "3-rps", "--joints", "=1"], ["name=value"]),
    ("run-missing-file", None, ["run", "{root}/nope.yaml", "--out", "{out}"], ["cannot read"]),
    ("run-folder-as-file", None, ["run", "{root}", "--out", "{out}"], ["is a folder"]),
    ("study-jobs-zero", yaml_of(STUDY), ["study", "{f}", "--out", "{out}", "--jobs", "0"], ["--jobs"]),
    ("study-executor", yaml_of(STUDY), ["study", "{f}", "--out", "{out}", "--executor", "mpi"], ["--executor"]),
    ("check-subset", None, ["check", "{out}", "--subset", "some"], ["--subset"]),
    ("check-missing", None, ["check", "{root}/nope"], ["no such results folder"]),
    ("report-missing", None, ["report", "{root}/nope"], ["no such results folder"]),
    ("reproduce-missing", None, ["reproduce", "--configs", "{root}/nope", "--out", "{out}"], ["not a folder"]),
    ("unknown-command", None, ["frobnicate"], ["No such command"]),
    ("unknown-option", None, ["run", "--colour"], ["--colour"]),
    # -- output locations --------------------------------------------------------------------------------
    ("out-is-file", yaml_of(BASE), ["run", "{f}", "--out", "{root}/afile"], ["is a file"]),
    ("out-below-file", yaml_of(BASE), ["run", "{f}", "--out", "{root}/afile/sub"], ["is a file"]),
    ("out-unwritable", yaml_of(BASE), ["run", "{f}", "--out", "/proc/fkopt-out"], ["cannot write"]),
    ("out-symlink-escape", with_(BASE, paper="link"), ["run", "{f}", "--out", "{out}"], ["outside"]),
    ("out-result-is-file", with_(BASE, paper="test", name="afile"), ["run", "{f}", "--out", "{out}"], ["is a file"]),
    ("out-not-results", with_(BASE, paper="test", name="notes"), ["run", "{f}", "--out", "{out}"],
     ["not a results folder"]),
    ("out-other-config", with_(BASE, name="small", seed=99), ["run", "{f}", "--out", "{out}"], ["--force"]),
    ("out-second-bad", yaml_of(BASE), ["run", "{f}", "{root}/nope.yaml", "--out", "{out}"], ["cannot read"]),
    ("study-out-file", yaml_of(STUDY), ["study", "{f}", "--out", "{root}/afile"], ["is a file"]),
    ("study-other-config", with_(STUDY, name="small", seed=99), ["study", "{f}", "--out", "{out}"], ["--force"]),
    ("bench-out-file", None, ["bench", "--quick", "--out", "{root}/afile"], ["is a file"]),
    ("export-out-file", None, ["export", "{out}/test", "--format", "ioh", "--out", "{root}/afile"], ["not a folder"]),
    ("export-out-below-file", None, ["export", "{out}/test", "--format", "ioh", "--out", "{root}/afile/x"], ["is a file"]),
    ("export-out-in-results", None, ["export", "{out}/test", "--format", "ioh", "--out", "{out}/test/ioh"],
     ["outside the results folder"]),
    ("export-out-not-export", None, ["export", "{out}/test", "--format", "ioh", "--out", "{root}/outside"],
     ["not written by fkopt export"]),
    ("reproduce-out-file", None, ["reproduce", "--configs", "{root}/configs", "--out", "{root}/afile"], ["is a file"]),
    ("reproduce-clash", None, ["reproduce", "--configs", "{root}/clash", "--out", "{out}"], ["paper/name must differ"]),
    ("report-corrupt-meta", None, ["report", "{root}/corrupt"], ["meta.json", "unreadable"]),
    # -- issue 30: huge finite numbers in configs and geometry (|v| <= 1e9) ----------------------------
    ("case-joints-1e300", with_(BASE, cases=[{"joints": {"d1": 1e300, "d2": 600, "d3": 600}}]),
     ["run", "{f}", "--out", "{out}"], ["cases[0].joints", "'d1'", "|value| <= 1e+09"]),
    ("case-pose-1e300", with_(BASE, cases=[{"pose": {"alpha": 0, "beta": 0, "z": 1e300}}]),
     ["run", "{f}", "--out", "{out}"], ["cases[0].pose", "'z'", "1e+09"]),
    ("assembly-joints-1e300", with_(ASSEMBLY, joints={"d1": 1e300, "d2": 1e300, "d3": 1e300}),
     ["run", "{f}", "--out", "{out}"], ["joints", "'d1'", "1e+09"]),
    ("geometry-1e300", "ra: 1.0e+300\n", ["ik", "3-rps", "--pose", "alpha=0,beta=0,z=600", "--geometry", "{f}"],
     ["geometry.ra", "|value| <= 1e+09"]),
    ("config-geometry-1e300", with_(BASE, mechanism={"name": "3-rps", "geometry": {"rb": 2e9}}),
     ["run", "{f}", "--out", "{out}"], ["geometry.rb", "1e+09"]),
]


def snapshot(root: Path) -> dict:
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file() and not p.is_symlink()}


@pytest.fixture(scope="module")
def sandbox(tmp_path_factory):
    """A sandbox with previous results (an experiment and a study), a decoy ``configs/`` and
    folders that hostile inputs aim at."""
    root = tmp_path_factory.mktemp("hostile")
    out = root / "out"
    (root / "configs").mkdir()
    (root / "configs" / "keep.yaml").write_text(yaml_of(BASE))
    outside = root / "outside"
    outside.mkdir()
    (outside / "important.txt").write_text("do not touch\n")
    (root / "afile").write_text("a file\n")
    from fkopt.cli import main
    for name, data, cmd in (("small", BASE, "run"), ("small", STUDY, "study")):
        cfg = root / f"prev-{cmd}.yaml"
        cfg.write_text(yaml_of({**data, "name": name}))
        with pytest.MonkeyPatch.context() as patch:     # in this process: a second start-up checks nothing here
            patch.setattr(sys, "argv", ["fkopt", cmd, str(cfg), "--out", str(out), "-q"])
            main()                                      # returns on success, exits otherwise
    (out / "test" / "afile").write_text("a file where a result would go\n")
    (out / "test" / "notes").mkdir()
    (out / "test" / "notes" / "todo.txt").write_text("not a result\n")
    (out / "link").symlink_to(outside, target_is_directory=True)
    clash = root / "clash"
    clash.mkdir()
    for i in (1, 2):
        (clash / f"c{i}.yaml").write_text(yaml_of(BASE))
    corrupt = root / "corrupt" / "paper" / "exp"
    corrupt.mkdir(parents=True)
    (corrupt / "meta.json").write_text("{not json")
    (corrupt / "summary.csv").write_text("case,algorithm\n")
    (root / "inputs").mkdir()
    return root


@pytest.mark.parametrize("case", CORPUS, ids=[c[0] for c in CORPUS])
def test_hostile_input(case, sandbox, cli, monkeypatch):
    ident, content, argv, fragments = case
    root, out = sandbox, sandbox / "out"
    f = root / "inputs" / f"{ident}.yaml"
    if content is not None:
        (f.write_bytes if isinstance(content, bytes) else f.write_text)(content)
    before = snapshot(root)
    monkeypatch.chdir(root)          # a relative path written by mistake would land in the sandbox
    code, stdout, err = cli(*[a.format(f=f, out=out, root=root) for a in argv])
    lines = err.strip().splitlines()
    assert code == 2, (code, err)
    assert len(lines) == 1, err
    assert lines[0].startswith("fkopt: error: ") and "Traceback" not in err + stdout
    message = lines[0].replace(str(f), "FILE")      # fragments must not match the file's own name
    for frag in fragments:
        assert frag in message, lines[0]
    assert snapshot(root) == before, "a hostile input wrote or changed a file"
    assert not any(p.name.startswith(".fkopt-probe") or ".new-" in p.name for p in root.rglob(".*"))


def test_corpus_is_large_enough():
    assert len(CORPUS) >= 60


def test_check_with_corrupt_meta_fails_with_status_1(sandbox, cli):
    code, _, err = cli("check", str(sandbox / "corrupt"), "-q")
    assert code == 1
    assert "meta.json" in err and "Traceback" not in err
    assert err.strip().splitlines()[-1].startswith("fkopt: check failed:")


def test_check_with_missing_meta_is_a_failure(sandbox, tmp_path, cli):
    import shutil
    results = tmp_path / "results"
    shutil.copytree(sandbox / "out" / "test" / "small", results / "test" / "small")
    (results / "test" / "small" / "meta.json").unlink()
    code, _, err = cli("check", str(results), "-q")
    assert code == 1 and "test/small: meta.json" in err and "missing" in err


# == issue 19: hostile inputs, second round ========================================================
# Each section reproduces a reported failure; every test failed before its fix.

def one_line_error(result, *fragments) -> str:
    """``result`` of ``cli(...)`` is exit 2 with exactly one ``fkopt: error:`` line holding ``fragments``."""
    code, out, err = result
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("fkopt: error: "), (code, err[-2000:])
    assert "Traceback" not in out + err
    for frag in fragments:
        assert frag in lines[0], lines[0]
    return lines[0]


@pytest.fixture(scope="module")
def finished_study_once(tmp_path_factory):
    """The folder ``finished_study`` copies: ``fkopt study`` run once per module (the study and its
    figures cost seconds; some 40 tests each spoil their own copy)."""
    from fkopt.cli import main
    root = tmp_path_factory.mktemp("finished-study")
    cfg = root / "s.yaml"
    cfg.write_text(yaml_of({**STUDY, "name": "small"}))
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(sys, "argv", ["fkopt", "study", str(cfg), "--out", str(root / "out"), "-q"])
        main()                                  # returns on success, exits otherwise
    outside = root / "outside"
    outside.mkdir()
    (outside / "keep.txt").write_text("outside --out\n")
    return root


@pytest.fixture
def finished_study(tmp_path, finished_study_once):
    """A finished study ``OUT/studies/small`` (2 poses, 1 task), its config, and an outside folder: a
    fresh copy of ``finished_study_once`` in this test's ``tmp_path`` (its files hold no absolute path)."""
    import shutil
    shutil.copytree(finished_study_once, tmp_path, symlinks=True, dirs_exist_ok=True)
    out = tmp_path / "out"
    return tmp_path / "s.yaml", out, out / "studies" / "small", tmp_path / "outside"


def _partial_with_a_task(out: Path, final: Path) -> Path:
    """An unfinished run's .partial holding the finished study's task files (as if interrupted)."""
    import shutil
    work = final.parent / f".{final.name}.partial"
    shutil.copytree(final / "tasks", work / "tasks")
    return work


# -- class 1: no write through a symbolic link inside --out ---------------------------------------
@pytest.mark.parametrize("link", ["partial", "tasks"])
def test_study_resume_refuses_partial_links_outside(finished_study, cli, link):
    cfg, out, final, outside = finished_study
    work = final.parent / f".{final.name}.partial"
    if link == "partial":
        work.symlink_to(outside, target_is_directory=True)
    else:
        work.mkdir()
        (work / "tasks").symlink_to(outside, target_is_directory=True)
    before, outside_before = snapshot(final), snapshot(outside)
    one_line_error(cli("study", cfg, "--out", out, "-q", "--resume"), "outside")
    assert snapshot(outside) == outside_before and sorted(p.name for p in outside.iterdir()) == ["keep.txt"]
    assert snapshot(final) == before and not (final / "tasks").is_symlink()


def test_study_resume_refuses_a_task_file_linked_outside(finished_study, cli):
    cfg, out, final, outside = finished_study
    task = next((final / "tasks").glob("a*.json"))
    (outside / task.name).write_bytes(task.read_bytes())
    task.unlink()
    task.symlink_to(outside / task.name)
    one_line_error(cli("study", cfg, "--out", out, "-q", "--resume"), "outside")


@pytest.mark.parametrize("target", ["REPORT.md", "index.csv", "studies/claims.csv", "studies/timing_claims.csv"])
def test_report_refuses_files_linked_outside(finished_study, cli, target):
    _, out, _, outside = finished_study
    victim = outside / "keep.txt"
    (out / target).unlink(missing_ok=True)
    (out / target).symlink_to(victim)
    one_line_error(cli("report", out), "outside")
    assert victim.read_text() == "outside --out\n"


@pytest.mark.parametrize("scheduler", [None, "tcp://127.0.0.1:1"], ids=["link", "unreachable-scheduler"])
def test_suite_resume_refuses_links_and_keeps_its_tasks(tmp_path, monkeypatch, scheduler):
    """The kinbench suite's .partial: a link outside --out is refused; an unreachable scheduler
    is one line before the finished tasks are touched."""
    monkeypatch.syspath_prepend(str(Path(__file__).parent))
    from test_kinbench import tiny
    from fkopt.errors import FkoptError
    from fkopt.run.pipeline import load_any, run_config
    from fkopt.kinbench.kind import work_folder
    path = tiny(tmp_path)
    out = tmp_path / "out"
    work = work_folder(out, load_any(path))
    work.parent.mkdir(parents=True)
    outside = tmp_path / "outside"
    outside.mkdir()
    if scheduler is None:
        work.symlink_to(outside, target_is_directory=True)
        with pytest.raises(FkoptError, match="outside"):
            run_config(load_any(path), out, source=str(path), resume=True)
        assert list(outside.iterdir()) == []
    else:
        pytest.importorskip("dask.distributed")
        (work / "tasks").mkdir(parents=True)
        (work / "tasks" / "p0-s0.json").write_text("{}")
        with pytest.raises(FkoptError, match="--scheduler"):
            run_config(load_any(path), out, source=str(path), resume=True, executor="dask", scheduler=scheduler)
        assert (work / "tasks" / "p0-s0.json").read_text() == "{}"


@pytest.mark.parametrize("content", ["[]", '"text"', "7"])
def test_suite_resume_refuses_corrupt_task_files(tmp_path, monkeypatch, content):
    monkeypatch.syspath_prepend(str(Path(__file__).parent))
    from test_kinbench import tiny
    from fkopt.errors import FkoptError
    from fkopt.run.pipeline import load_any, run_config
    from fkopt.kinbench.kind import work_folder
    import hashlib
    path = tiny(tmp_path)
    work = work_folder(tmp_path / "out", load_any(path))
    (work / "tasks").mkdir(parents=True)
    task = work / "tasks" / "p0-s0.json"
    task.write_text(content)
    # even with its digest recorded (forged) in the manifest, the record itself is checked
    (work / "tasks" / "manifest.json").write_text(json.dumps(
        {"fingerprint": None, "tasks": {"p0-s0": hashlib.sha256(task.read_bytes()).hexdigest()}}))
    with pytest.raises(FkoptError, match="p0-s0.json"):
        run_config(load_any(path), tmp_path / "out", source=str(path), resume=True)
    assert task.read_text() == content            # nothing wiped: the user decides


def test_bench_refuses_bench_csv_linked_outside(tmp_path, cli):
    bench = tmp_path / "b"
    bench.mkdir()
    victim = tmp_path / "victim.csv"
    victim.write_text("keep\n")
    (bench / "bench.csv").symlink_to(victim)
    one_line_error(cli("bench", "--quick", "--section", "exact", "--out", bench), "outside")
    assert victim.read_text() == "keep\n"


def test_inside_guard_resolves_every_link(tmp_path):
    from fkopt.errors import FkoptError
    from fkopt.files import inside
    (tmp_path / "out" / "a").mkdir(parents=True)
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "out" / "a" / "ok").symlink_to(tmp_path / "out")          # a link that stays inside
    (tmp_path / "out" / "a" / "away").symlink_to(tmp_path / "elsewhere")
    (tmp_path / "out" / "loop").symlink_to(tmp_path / "out" / "loop")
    assert inside(tmp_path / "out", tmp_path / "out" / "a" / "ok" / "x.csv")
    for bad in ("a/away/x.csv", "a/../../elsewhere", "loop/x"):
        with pytest.raises(FkoptError):
            inside(tmp_path / "out", tmp_path / "out" / bad)


# -- class 2 and 6: resumed task files are verified, corrupt ones are one line ------------------------
def test_resume_refuses_an_edited_task_file(finished_study, cli):
    cfg, out, final, _ = finished_study
    task = next((final / "tasks").glob("a*.json"))
    rec = json.loads(task.read_text())
    rec["rows"]["final_fitness"][0] = 0.0           # a better-looking result, written by hand
    task.write_text(json.dumps(rec))
    before = snapshot(final)
    one_line_error(cli("study", cfg, "--out", out, "-q", "--resume"), task.name, "changed since")
    assert snapshot(final) == before


def test_check_fails_on_an_edited_study_task_file(finished_study, cli):
    _, out, final, _ = finished_study
    assert cli("check", out, "-q")[0] == 0
    task = next((final / "tasks").glob("a*.json"))
    rec = json.loads(task.read_text())
    rec["rows"]["final_fitness"][0] = 0.0
    task.write_text(json.dumps(rec))
    code, _, err = cli("check", out, "-q")
    assert code == 1 and f"tasks/{task.name}" in err and "changed since written" in err, err


@pytest.mark.parametrize("content", ["[]", '{"fingerprint": "x"}', '"text"', '{"id": 5}', "{not json"],
                         ids=["list", "no-id", "string", "id-number", "garbage"])
def test_resume_refuses_corrupt_task_files(finished_study, cli, content):
    cfg, out, final, _ = finished_study
    work = _partial_with_a_task(out, final)
    task = next((work / "tasks").glob("a*.json"))
    task.write_text(content)
    one_line_error(cli("study", cfg, "--out", out, "-q", "--resume"), task.name)
    assert task.read_text() == content            # nothing wiped: the user decides


@pytest.mark.parametrize("edit", ["list", "no-id", "shape", "strings", "other-task", "fitness-text", "fitness-nan",
                                  "fitness-inf", "evaluations-negative", "wall-inf", "pose-twice"])
def test_resume_checks_records_even_when_digests_were_forged(finished_study, cli, edit):
    """Someone who also rewrote manifest.json's digests still cannot slip a malformed record in."""
    import hashlib
    cfg, out, final, _ = finished_study
    work = _partial_with_a_task(out, final)
    task = next((work / "tasks").glob("a*.json"))
    rec = json.loads(task.read_text())
    if edit == "list":
        rec = []
    elif edit == "no-id":
        del rec["id"]
    elif edit == "shape":
        rec["rows"]["final_fitness"] = rec["rows"]["final_fitness"][:1]
    elif edit == "strings":
        rec["rows"][next(k for k in rec["rows"] if k.startswith("x_"))] = "abc"
    elif edit.startswith("fitness-"):           # issue 30: a value of the wrong type or range
        rec["rows"]["final_fitness"][0] = {"fitness-text": "x", "fitness-nan": float("nan"),
                                           "fitness-inf": float("inf")}[edit]
    elif edit == "evaluations-negative":
        rec["rows"]["evaluations"][0] = -5
    elif edit == "wall-inf":
        rec["wall_s"] = float("inf")
    elif edit == "pose-twice":                 # one pose's rows in place of another's
        rec["rows"]["pose"] = [rec["rows"]["pose"][0]] * len(rec["rows"]["pose"])
    else:
        rec["task"]["stop"] = 1
    task.write_text(json.dumps(rec))
    manifest = json.loads((work / "tasks" / "manifest.json").read_text())
    manifest["tasks"][task.stem] = hashlib.sha256(task.read_bytes()).hexdigest()
    (work / "tasks" / "manifest.json").write_text(json.dumps(manifest))
    one_line_error(cli("study", cfg, "--out", out, "-q", "--resume"), task.name)


def test_resume_reuses_verified_tasks(finished_study, cli):
    cfg, out, final, _ = finished_study
    before = snapshot(final)
    code, stdout, err = cli("study", cfg, "--out", out, "--resume")
    assert code == 0, err
    assert "reused" in stdout
    assert {k: v for k, v in snapshot(final).items() if k.endswith(".csv") and "timing" not in k} == \
        {k: v for k, v in before.items() if k.endswith(".csv") and "timing" not in k}


def test_resume_drops_the_atomic_writers_leftover_temporaries(finished_study, cli):
    """A Ctrl-C (or a killed worker) between an atomic write's temporary file and its rename leaves
    ``.<name>.<random>.json`` beside the task files -- a parallel run under a real SIGINT did, and
    ``--resume`` then refused it as a task file changed since written. They are never tasks: resume
    removes them and reuses the real ones."""
    cfg, out, final, _ = finished_study
    tasks = final / "tasks"
    before = snapshot(final)
    for name in (".manifest.json.0d_0fy8a.json", ".a00.json.k3j9.json"):
        (tasks / name).write_text('{"half": ')
    code, stdout, err = cli("study", cfg, "--out", out, "--resume")
    assert code == 0, err
    assert "reused" in stdout
    assert not list((final / "tasks").glob(".*.json")) and not list(final.parent.glob(".*.partial"))
    assert {k: v for k, v in snapshot(final).items() if k.endswith(".csv") and "timing" not in k} == \
        {k: v for k, v in before.items() if k.endswith(".csv") and "timing" not in k}


@pytest.mark.parametrize("content", [b"claim,verdict\n\xff\xfe caf\xe9,holds\n", b"\x00\x01\x02garbage",
                                     b"a,b\n1,2\n"], ids=["latin1", "binary", "columns"])
def test_check_with_a_corrupt_claims_csv_is_one_failure_line(finished_study, cli, content):
    _, out, final, _ = finished_study
    (final.parent / "claims.csv").write_bytes(content)
    code, _, err = cli("check", out, "-q")
    assert code == 1 and "Traceback" not in err, err
    assert "claims.csv" in err.strip().splitlines()[-1]


# -- class 4 and 5: workers, Dask addresses -------------------------------------------------------
@pytest.mark.parametrize("address", ["not an address", "tcp://host:99999", "tcp://:80", "http://x:1/",
                                     "tcp://127.0.0.1:1"],
                         ids=["words", "port-range", "no-host", "http", "unreachable"])
def test_bad_scheduler_is_one_line_and_keeps_partial(finished_study, cli, address):
    pytest.importorskip("dask.distributed")
    cfg, out, final, _ = finished_study
    work = _partial_with_a_task(out, final)
    before = snapshot(work)
    one_line_error(cli("study", cfg, "--out", out, "-q", "--executor", "dask", "--scheduler", address,
                       "--resume"), "--scheduler")
    assert snapshot(work) == before


def test_workers_never_exceed_cpus_or_tasks():
    from fkopt.files import available_cpus
    from fkopt.run.executors import worker_count
    assert worker_count(10_000, 10_000) == available_cpus()
    assert worker_count(12, 2) == min(2, available_cpus())
    assert worker_count(1, 5) == 1


def test_jobs_10000_starts_no_more_processes_than_cpus(tmp_path, monkeypatch):
    """--jobs 10000 on this machine asks the pool for at most the CPUs (and the tasks)."""
    import concurrent.futures
    from fkopt.files import available_cpus
    from fkopt.run import executors
    asked = []

    class Pool(concurrent.futures.ThreadPoolExecutor):
        def __init__(self, max_workers, mp_context=None, initializer=None):
            asked.append(max_workers)   # the workers' initializer sets a signal handler: a thread cannot
            super().__init__(max_workers)
    monkeypatch.setattr(executors, "ProcessPoolExecutor", Pool)
    got = []
    executors.execute(abs, list(range(-6, 0)), jobs=10_000, on_result=got.append)
    assert sorted(got) == [1, 2, 3, 4, 5, 6]
    assert asked in ([], [min(6, available_cpus())]) and (asked or available_cpus() == 1)


# -- class 3: geometry, bounds and limits validated before computing --------------------------------
URDF_ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/><link name="l1"/><link name="tip"/>
  <joint name="q1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="{origin}" rpy="0 0 0"/><axis xyz="{axis}"/><limit lower="{lower}" upper="1.5" effort="1" velocity="1"/></joint>
  <joint name="q2" type="revolute"><parent link="l1"/><child link="tip"/>
    <origin xyz="0.3 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-1.5" upper="1.5" effort="1" velocity="1"/></joint>
</robot>
"""
DEGENERATE_6SPS = {"base": [[0, 0, 0] for _ in range(6)], "platform": [[0.1 * i, 0, 0] for i in range(6)]}
EARLY = [   # (id, config, fragments of the one line)
    ("bounds-overflow", {**BASE, "mechanism": {"name": "3-rps", "bounds": {"z": [-1e308, 1e308]}}},
     ["bounds.z", "too wide"]),
    ("bounds-huge-angles", {**BASE, "mechanism": {"name": "3-rps", "bounds": {"alpha": [-1e200, 1e200]}}},
     ["bounds.alpha"]),
    ("urdf-inf-limit", {**BASE, "mechanism": {"name": "urdf", "geometry": {"file": "{urdf_inf}"}},
                        "cases": {"random": 1, "seed": 1}}, ["q1", "limit"]),
    ("urdf-nan-origin", {**BASE, "mechanism": {"name": "urdf", "geometry": {"file": "{urdf_nan}"}},
                         "cases": {"random": 1, "seed": 1}}, ["q1", "origin"]),
    ("urdf-inf-axis", {**BASE, "mechanism": {"name": "urdf", "geometry": {"file": "{urdf_axis}"}},
                       "cases": {"random": 1, "seed": 1}}, ["q1", "axis"]),
    ("urdf-too-large", {**BASE, "mechanism": {"name": "urdf", "geometry": {"file": "{urdf_big}"}},
                        "cases": {"random": 1, "seed": 1}}, ["larger than"]),
    ("6sps-degenerate", {**BASE, "mechanism": {"name": "6-sps", "geometry": DEGENERATE_6SPS},
                         "cases": {"random": 1, "seed": 1}}, ["degenerate", "coincide"]),
    ("plugin-mech-inf-bounds", {**BASE, "mechanism": {"name": "hostile_plugins:InfiniteBounds"},
                                "cases": {"random": 1, "seed": 1}}, ["InfiniteBounds", "finite"]),
    ("plugin-mech-raises", {**BASE, "mechanism": {"name": "hostile_plugins:RaisingMech"},
                            "cases": {"random": 1, "seed": 1}}, ["RaisingMech", "ZeroDivisionError"]),
    ("plugin-mech-shape", {**BASE, "mechanism": {"name": "hostile_plugins:WrongShapeMech"},
                           "cases": {"random": 1, "seed": 1}}, ["WrongShapeMech", "shape"]),
    # -- class 4 and 5: adapters' parameters and populations, every algorithm before the first ----------
    ("scipy-de-popsize", {**BASE, "algorithms": [{"name": "scipy:differential_evolution",
                                                   "params": {"popsize": 3_000_000}}]},
     ["scipy:differential_evolution", "exceeds the run's budget"]),
    ("scipy-da-maxiter", {**BASE, "algorithms": [{"name": "scipy:dual_annealing", "params": {"maxiter": -1}}]},
     ["maxiter", "whole number"]),
    ("scipy-da-visit", {**BASE, "algorithms": [{"name": "scipy:dual_annealing", "params": {"visit": 100}}]},
     ["visit"]),
    ("scipy-de-strategy-second", {**BASE, "algorithms": [{"name": "hostile_plugins:Marks"},
                                                         {"name": "scipy:differential_evolution",
                                                          "params": {"strategy": "nope"}}]},
     ["scipy:differential_evolution", "strategy"]),
    ("scipy-de-popsize-memory", {**BASE, "algorithms": [{"name": "scipy:differential_evolution",
                                                         "params": {"popsize": 300_000_000, "evaluations": 10**12}}]},
     ["GiB of memory"]),
    ("pymoo-pop-size", {**BASE, "algorithms": [{"name": "pymoo:DE", "params": {"pop_size": 2_000_000}}]},
     ["pymoo:DE", "exceeds the run's budget"]),
    # -- class 7: plug-in algorithms contained -------------------------------------------------------------
    ("plugin-raises", {**BASE, "algorithms": [{"name": "hostile_plugins:Raises"}]}, ["Raises", "RuntimeError", "boom"]),
    ("plugin-returns-none", {**BASE, "algorithms": [{"name": "hostile_plugins:ReturnsNone"}]},
     ["ReturnsNone", "NoneType"]),
    ("plugin-bad-state", {**BASE, "algorithms": [{"name": "hostile_plugins:BadState"}]}, ["BadState", "shape"]),
    ("plugin-nan-fitness", {**BASE, "algorithms": [{"name": "hostile_plugins:NaNFitness"}]}, ["NaNFitness", "NaN"]),
    ("plugin-out-of-bounds", {**BASE, "algorithms": [{"name": "hostile_plugins:OutOfBounds"}]},
     ["OutOfBounds", "outside the bounds"]),
    ("plugin-negative-evals", {**BASE, "algorithms": [{"name": "hostile_plugins:NegativeEvals"}]},
     ["NegativeEvals", "evaluations"]),
    ("plugin-system-exit", {**BASE, "algorithms": [{"name": "hostile_plugins:Exits"}]}, ["Exits", "SystemExit"]),
    ("plugin-wrong-record", {**BASE, "algorithms": [{"name": "hostile_plugins:WrongRecord"}]},
     ["WrongRecord", "shape"]),
    ("plugin-init-raises", {**BASE, "algorithms": [{"name": "hostile_plugins:InitRaises"}]},
     ["InitRaises", "KeyError"]),
    ("plugin-module-getattr", {**BASE, "algorithms": [{"name": "hostile_lazy:Anything"}]}, ["no attribute"]),
]

PLUGINS = r"""
import numpy as np
from fkopt.algorithms.base import Algorithm, RunRecord, State
from fkopt.mechanisms.base import ParallelMechanism
from fkopt.mechanisms.rps3 import ThreeRPS


class Good(Algorithm):
    name = "good"

    def initialize(self, problem, population, streams, x0, iterations):
        x = np.broadcast_to(problem.bounds.mean(axis=1), (streams.runs, population, problem.dim)).copy()
        return State(x=x, f=problem.fitness(x), evaluations=np.full(streams.runs, population))

    def iterate(self, state, problem, streams):
        state.evaluations = state.evaluations + state.x.shape[1]


class Marks(Good):
    # leaves a mark when it starts: a config refused up front never gets here

    def initialize(self, *args):
        import pathlib
        pathlib.Path(__file__).with_name("started").write_text("yes")
        return super().initialize(*args)


class Raises(Good):
    def iterate(self, state, problem, streams):
        raise RuntimeError("boom")


class InitRaises(Good):
    def __init__(self, **params):
        raise KeyError("config")


class ReturnsNone(Good):
    def initialize(self, *args):
        return None


class BadState(Good):
    def iterate(self, state, problem, streams):
        state.x = state.x[:, :, :1]


class NaNFitness(Good):
    def iterate(self, state, problem, streams):
        state.f = np.full_like(state.f, np.nan)


class OutOfBounds(Good):
    def iterate(self, state, problem, streams):
        state.x = state.x + 1e6


class NegativeEvals(Good):
    def iterate(self, state, problem, streams):
        state.evaluations = state.evaluations * 0 - 5


class Exits(Good):
    def iterate(self, state, problem, streams):
        raise SystemExit(0)


class WrongRecord(Good):
    def minimize(self, problem, *, population, iterations, streams, **kw):
        n = streams.runs
        return RunRecord(best_x=np.zeros((n, 1)), best_f=np.zeros(n), history=np.zeros((n, iterations + 1)),
                         x_history=None, evaluation_history=np.zeros((n, iterations + 1), dtype=int),
                         iterations_done=np.full(n, iterations))


class InfiniteBounds(ThreeRPS):
    name = "infinite"
    default_bounds = {**ThreeRPS.default_bounds, "z": (-np.inf, np.inf)}


class RaisingMech(ThreeRPS):
    name = "raising"

    def ik(self, poses):
        return 1 / 0


class WrongShapeMech(ThreeRPS):
    name = "wrong-shape"

    def ik(self, poses):
        return np.zeros(2)
"""

LAZY = r"""
import pathlib
MARK = pathlib.Path(__file__).with_name("getattr-called")


def __getattr__(name):
    MARK.write_text(name)
    raise AttributeError(name)
"""


@pytest.fixture
def plugin_dir(tmp_path, monkeypatch):
    """Importable plug-in modules (hostile_plugins, hostile_lazy) for this test only."""
    import importlib
    folder = tmp_path / "plugins"
    folder.mkdir()
    (folder / "hostile_plugins.py").write_text(PLUGINS)
    (folder / "hostile_lazy.py").write_text(LAZY)
    monkeypatch.syspath_prepend(str(folder))
    for name in ("hostile_plugins", "hostile_lazy"):
        sys.modules.pop(name, None)
    importlib.invalidate_caches()
    yield folder
    for name in ("hostile_plugins", "hostile_lazy", "hostile_marker"):
        sys.modules.pop(name, None)


@pytest.mark.parametrize("case", EARLY, ids=[c[0] for c in EARLY])
def test_bad_input_fails_before_any_work(case, tmp_path, plugin_dir, cli):
    ident, config, fragments = case
    files = {"urdf_inf": URDF_ARM.format(origin="0 0 0.1", axis="0 0 1", lower="-inf"),
             "urdf_nan": URDF_ARM.format(origin="nan 0 0.1", axis="0 0 1", lower="-1.5"),
             "urdf_axis": URDF_ARM.format(origin="0 0 0.1", axis="0 inf 1", lower="-1.5"),
             "urdf_big": URDF_ARM.format(origin="0 0 0.1", axis="0 0 1", lower="-1.5")
             + "<!-- " + "x" * (5 << 20) + " -->\n"}
    for key, text in files.items():
        (tmp_path / f"{key}.urdf").write_text(text)
    text = yaml_of(config)
    for key in files:
        text = text.replace("{" + key + "}", str(tmp_path / f"{key}.urdf"))
    cfg = tmp_path / "c.yaml"
    cfg.write_text(text)
    out = tmp_path / "out"
    one_line_error(cli("run", cfg, "--out", out, "-q"), *fragments)
    assert not out.exists() or not any(p.is_file() for p in out.rglob("*")), "a refused config wrote a file"
    assert not (plugin_dir / "getattr-called").exists(), "a module-level __getattr__ was called"
    assert not (plugin_dir / "started").exists(), "an algorithm started before every one was validated"


def test_degenerate_6sps_is_one_line_in_fk(tmp_path, cli):
    geo = tmp_path / "g.yaml"
    geo.write_text(yaml_of(DEGENERATE_6SPS))
    one_line_error(cli("fk", "6-sps", "--joints", "l1=1,l2=1,l3=1,l4=1,l5=1,l6=1", "--geometry", geo),
                   "degenerate")


def test_a_leg_of_length_zero_does_not_divide_by_zero():
    """Dietmaier's first base and platform joints coincide at the zero pose (leg 1 of length 0)."""
    from fkopt.mechanisms.sps6 import SixSPS
    lengths, J = SixSPS().ik_jacobian1([0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    assert lengths[0] == 0.0 and J[0][:3] == [0.0, 0.0, 0.0]


def test_good_plugin_still_runs(tmp_path, plugin_dir, cli):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml_of({**BASE, "algorithms": [{"name": "hostile_plugins:Good"}]}))
    code, _, err = cli("run", cfg, "--out", tmp_path / "out", "-q")
    assert code == 0, err


def test_plugin_failure_in_a_study_worker_is_one_line(tmp_path, plugin_dir, cli):
    """SystemExit(0) inside iterate, in a study: not exit 0 with nothing written."""
    cfg = tmp_path / "s.yaml"
    cfg.write_text(yaml_of({**STUDY, "algorithms": [{"name": "hostile_plugins:Exits"}]}))
    one_line_error(cli("study", cfg, "--out", tmp_path / "out", "-q"), "Exits", "SystemExit")


# -- class 7: fkopt check imports only registered names -------------------------------------------
def test_check_does_not_import_modules_named_in_stored_results(finished_study, plugin_dir, cli):
    _, out, final, _ = finished_study
    (plugin_dir / "hostile_marker.py").write_text(
        "import pathlib\npathlib.Path(__file__).with_name('imported').write_text('yes')\n")
    meta = json.loads((final / "meta.json").read_text())
    meta["config"]["algorithms"][0]["name"] = "hostile_marker:Anything"
    (final / "meta.json").write_text(json.dumps(meta))
    code, _, err = cli("check", out, "-q")
    assert code in (1, 2) and "Traceback" not in err and "--allow-plugins" in err, err
    assert not (plugin_dir / "imported").exists(), "fkopt check imported a module named by meta.json"
    code, _, err = cli("check", out, "-q", "--allow-plugins")
    assert code != 0 and (plugin_dir / "imported").exists()       # asked for: imported (then refused)


def test_registered_only_refuses_references_but_not_built_ins():
    from fkopt import registry
    from fkopt.errors import FkoptError
    with registry.registered_only():
        assert registry.algorithm_class("gabc").__name__ == "GABC"
        with pytest.raises(FkoptError, match="allow-plugins"):
            registry.algorithm_class("fkopt.algorithms.gabc:GABC")
    assert registry.algorithm_class("fkopt.algorithms.gabc:GABC").__name__ == "GABC"


# -- class 8: two runs into one paper/name at once ------------------------------------------------
def _merge_with(monkeypatch, experiment_kind, merge) -> None:
    """The registered experiment kind with another merge (the pipeline looks kinds up by name)."""
    import dataclasses

    from fkopt.run.kinds import KINDS
    monkeypatch.setitem(KINDS, "experiment", dataclasses.replace(experiment_kind.EXPERIMENT, merge=merge))


def test_a_second_run_of_the_same_name_meanwhile_is_refused(tmp_path, cli, monkeypatch):
    """Run A computes; meanwhile run B of the same paper/name starts: B is refused with one line
    (A holds OUT/<paper>/.<name>.lock), A publishes, and no lock file is left behind."""
    from fkopt.errors import FkoptError
    from fkopt.kinds.experiment import kind as experiment_kind
    from fkopt.run.pipeline import from_dict, run_config
    out = tmp_path / "out"
    cfg = tmp_path / "a.yaml"
    cfg.write_text(yaml_of({**BASE, "name": "same"}))
    real, refused = experiment_kind.merge_experiment, []

    def meanwhile(config, *args, **kw):
        if config.seed == 1:
            with pytest.raises(FkoptError, match="another fkopt run is computing this result") as err:
                run_config(from_dict({**BASE, "name": "same", "seed": 99}, "other"), out)
            refused.append(str(err.value))
        return real(config, *args, **kw)
    _merge_with(monkeypatch, experiment_kind, meanwhile)
    (out / "test").mkdir(parents=True)
    (out / "test" / ".same.lock").write_text("")      # a stale lock of a killed run: taken over
    assert cli("run", cfg, "--out", out, "-q")[0] == 0
    assert refused and len(refused[0].splitlines()) == 1
    assert json.loads((out / "test" / "same" / "meta.json").read_text())["seed"] == 1
    assert not (out / "test" / ".same.lock").exists()


def test_a_result_written_meanwhile_by_another_run_is_not_replaced(tmp_path, cli, monkeypatch):
    """Where the lock cannot hold (a file system without flock, an older fkopt): run A (seed 1)
    computes; meanwhile run B (seed 99) publishes into the same paper/name. A must not replace
    B's result without --force: it is refused at publish time, one line."""
    import contextlib
    from fkopt.kinds.experiment import kind as experiment_kind
    from fkopt.run import pipeline as kinds
    from fkopt.run.pipeline import from_dict, run_config
    monkeypatch.setattr(kinds, "run_lock", lambda out, folder: contextlib.nullcontext())
    out = tmp_path / "out"
    cfg = tmp_path / "a.yaml"
    cfg.write_text(yaml_of({**BASE, "name": "same"}))
    real = experiment_kind.merge_experiment

    def meanwhile(config, *args, **kw):
        result = real(config, *args, **kw)
        if config.seed == 1:              # the other run finishes while this one computes
            run_config(from_dict({**BASE, "name": "same", "seed": 99}, "other"), out)
        return result
    _merge_with(monkeypatch, experiment_kind, meanwhile)
    one_line_error(cli("run", cfg, "--out", out, "-q"), "--force", "another fkopt run")
    assert json.loads((out / "test" / "same" / "meta.json").read_text())["seed"] == 99
    _merge_with(monkeypatch, experiment_kind, real)
    assert cli("run", cfg, "--out", out, "-q", "--force")[0] == 0      # asked for: replaced
    assert json.loads((out / "test" / "same" / "meta.json").read_text())["seed"] == 1


# -- interrupted reruns keep the previous result ----------------------------------------------------
SLOW = {**BASE, "name": "small", "population": 40, "iterations": 3000, "runs": 60,
        "algorithms": [{"name": "abc"}, {"name": "gabc"}, {"name": "pso"}]}
SLOW_STUDY = {**STUDY, "name": "small", "poses": {"uniform": 400, "seed": 1}, "population": 20,
              "iterations": 400, "runs": 5, "chunk": 400}


def _interrupt(tmp_path, prev, slow, command, how):
    out = tmp_path / "out"
    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml_of(prev))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(Path(__file__).resolve().parents[1]),
                                                                         os.environ.get("PYTHONPATH")]))}
    proc = subprocess.run([sys.executable, "-m", "fkopt.cli", command, str(cfg), "--out", str(out), "-q"],
                          capture_output=True, text=True, timeout=300, env=env)
    assert proc.returncode == 0, proc.stderr
    before = snapshot(out)
    cfg.write_text(yaml_of(slow))
    p = subprocess.Popen([sys.executable, "-m", "fkopt.cli", command, str(cfg), "--out", str(out), "-q",
                          "--force"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True, env=env)
    # interrupt once it computes: its lock file (OUT/<paper>/.<name>.lock) appears after imports and
    # validation (about a second on an idle machine, far longer on a loaded one), then half a second
    wait_while_running(p, lambda: list(out.glob(f"*/.{slow['name']}.lock")), 240)
    time.sleep(0.5)
    assert p.poll() is None, "the rerun finished before it could be interrupted; make SLOW slower"
    os.killpg(p.pid, how)
    _, err = p.communicate(timeout=60)
    # hidden siblings (.<name>.partial: a study's finished tasks for --resume; .<name>.new-*: a
    # killed writer's scratch) are not results
    after = {k: v for k, v in snapshot(out).items() if not any(part.startswith(".") for part in k.split("/"))}
    assert after == before, f"previous result changed (exit {p.returncode}): {err[-500:]}"
    if how == signal.SIGINT:
        assert p.returncode == 130 and "Traceback" not in err and len(err.strip().splitlines()) == 1


AT_NUMBA_EVENT = """\
import os, signal, sys
from numba.core import event
kind, n, sent = sys.argv[1], int(sys.argv[2]), sys.argv[3]
seen = [0]

class Send(event.Listener):
    def on_start(self, ev):
        seen[0] += 1
        if seen[0] == n:
            open(sent, "w").close()
            os.kill(os.getpid(), signal.SIGINT)

    def on_end(self, ev):
        pass

event.register(kind, Send())
from fkopt.cli import entry_point
sys.argv = ["fkopt", *sys.argv[4:]]
entry_point.main()
"""


@pytest.mark.parametrize("kind,n", [("numba:llvm_lock", 400)])
def test_ctrl_c_inside_numbas_compiler_is_one_line_and_exit_130(tmp_path, kind, n):
    """A SIGINT at the start of numba's n-th compiler event, with a cold cache (so the run compiles).
    Raised inside llvmlite it had left an object half built, whose finaliser then printed a
    traceback (llvm_lock 400, before the fix), and a CI run died of a segmentation fault: a Ctrl-C
    now waits for the compile to end (fkopt.numerics.jit.interrupts_deferred). The marker file
    shows the signal was sent."""
    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml_of(SLOW))
    (tmp_path / "at_numba_event.py").write_text(AT_NUMBA_EVENT)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"),
           "PYTHONPATH": os.pathsep.join(filter(None, [str(Path(__file__).resolve().parents[1]), str(tmp_path),
                                                       os.environ.get("PYTHONPATH")]))}
    sent = tmp_path / "sent"
    proc = subprocess.run([sys.executable, "-m", "at_numba_event", kind, str(n), str(sent), "run", str(cfg),
                           "--out", str(tmp_path / "out"), "-q"], capture_output=True, text=True, timeout=300, env=env)
    assert sent.exists(), "the run compiled fewer events than n: choose a smaller n"
    assert proc.returncode == 130, (proc.returncode, proc.stderr[-800:])
    assert len(proc.stderr.strip().splitlines()) == 1 and "Traceback" not in proc.stderr, proc.stderr[-800:]


def test_ctrl_c_inside_a_string_exec_still_exits_130(tmp_path):
    """CI saw a real run end by the signal (-2) after printing its line: the SIGINT had landed inside
    an ``exec`` of a string (as numba and dataclasses build code), which CPython marks as unhandled
    even though fkopt's entry point handles it. Here the command itself runs in such an ``exec``."""
    # run as a module (``python -m``, as the tests and the Makefile run fkopt): CPython checks the mark
    # only when the main module ran through runpy
    (tmp_path / "spin_cmd.py").write_text(
        "import sys\n"
        "from fkopt.cli import entry_point\n"
        "def spin(**_):\n"
        "    exec('import time\\nprint(\\'ready\\', flush=True)\\nwhile True: time.sleep(0.01)')\n"
        "entry_point.app = spin\n"
        "sys.argv = ['fkopt', 'run']\n"
        "entry_point.main()\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(Path(__file__).resolve().parents[1]),
                                                                         str(tmp_path), os.environ.get("PYTHONPATH")]))}
    p = subprocess.Popen([sys.executable, "-m", "spin_cmd"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True, env=env)
    assert p.stdout.readline().strip() == "ready"
    os.killpg(p.pid, signal.SIGINT)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130, (p.returncode, err)
    assert err.strip().splitlines() == ["fkopt: interrupted (previous results are kept)"]


@pytest.mark.parametrize("how", [signal.SIGINT, signal.SIGKILL], ids=["sigint", "kill-9"])
def test_interrupted_experiment_rerun_keeps_previous_result(tmp_path, how):
    _interrupt(tmp_path, {**BASE, "name": "small"}, SLOW, "run", how)


@pytest.mark.parametrize("how", [signal.SIGINT, signal.SIGKILL], ids=["sigint", "kill-9"])
def test_interrupted_study_rerun_keeps_previous_result(tmp_path, how):
    _interrupt(tmp_path, {**STUDY, "name": "small"}, SLOW_STUDY, "study", how)


def test_ctrl_c_of_a_parallel_run_keeps_its_tasks_and_resume_finishes_it(tmp_path):
    """The one runner under a real SIGINT to the process group (workers included): the finished
    task files stay with their digests, ``fkopt run --resume`` reuses them and computes only the
    rest, and the result is byte for byte that of an uninterrupted run."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(Path(__file__).resolve().parents[1]),
                                                                         os.environ.get("PYTHONPATH")]))}
    study = {**STUDY, "name": "cut", "poses": {"uniform": 48, "seed": 1}, "population": 20, "iterations": 300,
             "runs": 4, "chunk": 4}
    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml_of(study))
    run = [sys.executable, "-m", "fkopt.cli", "run", str(cfg), "-q"]
    assert subprocess.run([*run, "--out", str(tmp_path / "whole")], capture_output=True, timeout=300,
                          env=env).returncode == 0
    out = tmp_path / "out"
    manifest = out / "studies" / ".cut.partial" / "tasks" / "manifest.json"
    p = subprocess.Popen([*run, "--out", str(out), "--jobs", "2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True, start_new_session=True, env=env)
    # until some, not all, tasks are on disk
    wait_while_running(p, lambda: len(json.loads(manifest.read_text())["tasks"]) >= 2, 120)
    assert p.poll() is None, "the run finished before it could be interrupted"
    os.killpg(p.pid, signal.SIGINT)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err[-500:]
    assert not (out / "studies" / "cut").exists()
    # the manifest names a task's digest before its file appears (fkopt.run.tasks.TaskStore.add), so a
    # Ctrl-C between the two leaves a named task without a file, which --resume recomputes: the tasks
    # kept are the named ones whose file is on disk
    named = json.loads(manifest.read_text())["tasks"]
    kept = [k for k in named if (manifest.parent / f"{k}.json").exists()]
    assert 2 <= len(named) < 12 and len(named) - 1 <= len(kept) <= len(named)
    proc = subprocess.run([*run[:-1], "--out", str(out), "--resume"], capture_output=True, text=True, timeout=300,
                          env=env)
    assert proc.returncode == 0, proc.stderr
    assert f"resumed: {len(kept)} finished task(s) reused, {12 - len(kept)} computed" in proc.stdout
    for name in ("summary.csv", "runs.csv", "poses.csv", "ecdf.csv", "stats.csv"):
        assert (out / "studies" / "cut" / name).read_bytes() == (tmp_path / "whole" / "studies" / "cut" / name
                                                                 ).read_bytes(), name


def test_worker_processes_leave_ctrl_c_to_the_parent():
    """A terminal's Ctrl-C reaches every process of the group; a worker interrupted inside numba's
    compiler printed llvmlite's finaliser traceback beside fkopt's one line (CI), so workers ignore
    SIGINT and the parent, on its KeyboardInterrupt, terminates them."""
    from fkopt.run.executors import _processes
    seen = []
    _processes(signal.getsignal, [signal.SIGINT] * 4, 2, seen.append)
    assert seen == [signal.SIG_IGN] * 4
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler   # this process keeps its own


def test_a_ctrl_c_inside_a_finaliser_is_delivered_again_without_a_traceback(monkeypatch, capsys):
    """CPython cannot raise from ``__del__``: it printed "Exception ignored in" with a traceback and
    lost the interrupt. fkopt's hook re-delivers it to the main thread and prints nothing; other
    unraisable exceptions still reach Python's own hook."""
    from fkopt.cli.entry_point import interrupt_not_swallowed
    monkeypatch.setattr(sys, "unraisablehook", interrupt_not_swallowed)

    class Finalised:
        def __init__(self, error):
            self.error = error

        def __del__(self):
            raise self.error

    import threading
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        start = time.monotonic()
        with pytest.raises(KeyboardInterrupt):
            Finalised(KeyboardInterrupt())
            threading.Event().wait(30)   # blocked, as a parent waiting for its workers' results
        assert time.monotonic() - start < 20
    finally:
        signal.signal(signal.SIGINT, previous)
    assert capsys.readouterr().err == ""
    Finalised(ValueError("not an interrupt"))
    err = capsys.readouterr().err
    assert "Exception ignored in" in err and "ValueError: not an interrupt" in err


def test_the_finaliser_hook_chains_to_the_previous_one_and_main_puts_it_back(monkeypatch):
    """Other unraisable exceptions go to the hook installed before fkopt's (pytest's, when the tests
    call main in their own process), and main puts that hook back when it ends."""
    import functools
    from types import SimpleNamespace
    from fkopt.cli import entry_point
    seen = []
    monkeypatch.setattr(sys, "unraisablehook", seen.append)
    other = SimpleNamespace(exc_type=ValueError, exc_value=ValueError("x"), exc_traceback=None, err_msg=None,
                            object=None)
    entry_point.interrupt_not_swallowed(other, otherwise=seen.append)
    assert seen == [other]
    during = []
    monkeypatch.setattr(entry_point, "_main", lambda: during.append(sys.unraisablehook))
    entry_point.main()
    assert isinstance(during[0], functools.partial) and during[0].func is entry_point.interrupt_not_swallowed
    assert sys.unraisablehook == seen.append


def test_a_ctrl_c_in_a_finaliser_at_shutdown_prints_nothing(tmp_path):
    """While the interpreter shuts down no thread can start (nor should one): the hook stays silent
    instead of printing its own "Exception ignored in sys.unraisablehook"."""
    code = ("import sys\n"
            "from fkopt.cli.entry_point import interrupt_not_swallowed\n"
            "sys.unraisablehook = interrupt_not_swallowed\n"
            "class Finalised:\n"
            "    def __del__(self):\n"
            "        raise KeyboardInterrupt\n"
            "kept = Finalised()\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr


def test_workers_are_born_ignoring_ctrl_c():
    """Workers started while the parent ignores SIGINT keep ignoring it through spawn's exec, before
    any initializer runs (a worker importing fkopt for 0.3 s printed a traceback when Ctrl-C came
    then); the parent's own handler is back afterwards."""
    import concurrent.futures
    import multiprocessing
    from fkopt.files import sigint_handler
    before = signal.getsignal(signal.SIGINT)
    with sigint_handler(signal.SIG_IGN):             # as fkopt.run.executors starts its pool
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
        pool = concurrent.futures.ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn"))
        futures = [pool.submit(signal.getsignal, signal.SIGINT) for _ in range(2)]
    assert signal.getsignal(signal.SIGINT) is before
    assert [f.result() for f in futures] == [signal.SIG_IGN] * 2
    pool.shutdown()


def test_fkopt_run_refuses_other_config_unless_forced(tmp_path, cli):
    cfg = tmp_path / "c.yaml"
    out = tmp_path / "out"
    cfg.write_text(yaml_of({**BASE, "name": "small"}))
    assert cli("run", str(cfg), "--out", str(out), "-q")[0] == 0
    # title/printed/check changes are not result-changing: replaced without --force
    cfg.write_text(yaml_of({**BASE, "name": "small", "title": "renamed", "check": "full"}))
    assert cli("run", str(cfg), "--out", str(out), "-q")[0] == 0
    cfg.write_text(yaml_of({**BASE, "name": "small", "seed": 2}))
    code, _, err = cli("run", str(cfg), "--out", str(out), "-q")
    assert code == 2 and "--force" in err
    assert cli("run", str(cfg), "--out", str(out), "-q", "--force")[0] == 0
    assert json.loads((out / "test" / "small" / "meta.json").read_text())["seed"] == 2


def test_hidden_scratch_folders_are_not_results(tmp_path, cli):
    """A writer killed before its swap leaves a complete hidden copy: report and check skip it."""
    import shutil
    from fkopt.reproduce.store import Store
    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml_of({**BASE, "name": "small"}))
    out = tmp_path / "out"
    assert cli("run", str(cfg), "--out", str(out), "-q")[0] == 0
    shutil.copytree(out / "test" / "small", out / "test" / ".small.new-x1y2")
    assert [e.name for e in Store(out).experiments()] == ["small"]
    assert [e.name for e in Store(out).folders()] == ["small"]


def test_swap_keeps_previous_until_replaced(tmp_path):
    """write_atomically: a failing writer leaves the previous folder; a finished one replaces it;
    a result that appeared meanwhile is swapped out, not an error."""
    from fkopt.files import swap_into_place, write_atomically
    final = tmp_path / "r"
    write_atomically(final, lambda t: (t / "a.csv").write_text("1\n"))

    def broken(t):
        (t / "a.csv").write_text("half")
        raise RuntimeError("disk full")
    with pytest.raises(RuntimeError):
        write_atomically(final, broken)
    assert (final / "a.csv").read_text() == "1\n" and sorted(p.name for p in tmp_path.iterdir()) == ["r"]
    write_atomically(final, lambda t: (t / "b.csv").write_text("2\n"))
    assert sorted(p.name for p in final.iterdir()) == ["b.csv"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r"]
    new = tmp_path / ".r.new-x"
    new.mkdir()
    (new / "c.csv").write_text("3\n")
    swap_into_place(new, final)
    assert sorted(p.name for p in final.iterdir()) == ["c.csv"] and not new.exists()


# == issue 30: hostile inputs, third round ==========================================================
# Every file fkopt did not write in this run is read bounded (files.read_input) and validated.
import gzip as _gzip
import shutil as _shutil

SUITES = Path(__file__).resolve().parents[1] / "configs" / "suites"
MINI_SETS = "my-sets"


def mini_suite(root: Path, sets_folder: str = MINI_SETS, **over) -> Path:
    """A one-problem suite (mao2017-3rps, set uniform, 2 poses, lm) beside a copy of its pose sets
    under a private version name (so the released-version check does not mask what is tested)."""
    root.mkdir(parents=True, exist_ok=True)
    sets = root / sets_folder
    if not sets.exists():
        _shutil.copytree(SUITES / "kinbench-v1" / "mao2017-3rps", sets / "mao2017-3rps")
        manifest = json.loads((SUITES / "kinbench-v1" / "manifest.json").read_text())
        manifest["problems"] = {"mao2017-3rps": manifest["problems"]["mao2017-3rps"]}
        manifest["version"] = sets_folder
        (sets / "manifest.json").write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n")
    data = yaml.safe_load((SUITES / "kinbench.yaml").read_text())
    data.update(name="mini", pose_sets=sets_folder, problems=data["problems"][:1], sets=["uniform"], poses=2,
                runs=1, solvers=[{"name": "lm"}], budget_per_dim=50, bootstrap=100, quick=None)
    data.update(over)
    path = root / "mini.yaml"
    path.write_text(yaml_of(data))
    return path


def resign(sets: Path, rel: str) -> None:
    """Update the manifest's SHA-256 of ``rel`` (a forged signature: the file is then 'valid')."""
    manifest = json.loads((sets / "manifest.json").read_text())
    name = Path(rel).stem
    manifest["problems"]["mao2017-3rps"]["sets"][name]["sha256"] = hashlib.sha256((sets / rel).read_bytes()).hexdigest()
    (sets / "manifest.json").write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n")


def refused(cli, argv, root: Path, *fragments) -> str:
    """``fkopt argv`` is exit 2, one line holding ``fragments``, and nothing under ``root`` changed."""
    before = snapshot(root)
    line = one_line_error(cli(*argv), *fragments)
    assert snapshot(root) == before, "a refused input wrote or changed a file"
    return line


# -- pose sets: every malformed input is one line (findings 1, 3 and 5) ---------------------------
UNIFORM = f"{MINI_SETS}/mao2017-3rps/uniform.csv"


def _csv(text):
    def spoil(sets):
        (sets / "mao2017-3rps" / "uniform.csv").write_bytes(text if isinstance(text, bytes) else text.encode())
        resign(sets, "mao2017-3rps/uniform.csv")
    return spoil


def _manifest(change):
    def spoil(sets):
        m = json.loads((sets / "manifest.json").read_text())
        m = change(m)
        (sets / "manifest.json").write_text(json.dumps(m))
    return spoil


def _entry(change):
    return _manifest(lambda m: (change(m["problems"]["mao2017-3rps"]), m)[1])


def _link(target):
    def spoil(sets):
        f = sets / "mao2017-3rps" / "uniform.csv"
        f.unlink()
        f.symlink_to(target)
    return spoil


def _fifo(sets):
    f = sets / "mao2017-3rps" / "uniform.csv"
    f.unlink()
    os.mkfifo(f)


POSESET_CASES = [
    ("csv-empty", _csv(""), ["uniform.csv", "empty"]),
    ("csv-non-ascii", _csv("alpha,beta,z\n1,2,caf\u00e9\n"), ["uniform.csv", "not ASCII"]),
    ("csv-cell-text", _csv("alpha,beta,z\n1,2,<script>\n"), ["uniform.csv", "line 2", "not a number"]),
    ("csv-ragged", _csv("alpha,beta,z\n1,2,600\n1,2\n"), ["uniform.csv", "line 3", "needs 3"]),
    ("csv-nan", _csv("alpha,beta,z\n1,2,nan\n"), ["uniform.csv", "finite"]),
    ("csv-header", _csv("a,b,c\n1,2,600\n"), ["uniform.csv", "header", "alpha,beta,z"]),
    ("csv-poses-count", _csv("alpha,beta,z\n1,2,600\n"), ["poses", "has 1 poses"]),
    ("csv-fifo", _fifo, ["uniform.csv", "FIFO", "only regular files"]),
    ("csv-dev-zero", _link("/dev/zero"), ["uniform.csv", "outside"]),
    ("csv-folder", lambda s: ((s / "mao2017-3rps" / "uniform.csv").unlink(),
                              (s / "mao2017-3rps" / "uniform.csv").mkdir()), ["uniform.csv", "a folder"]),
    ("csv-link-outside", lambda s: _link(s.parent / "elsewhere.csv")(s), ["uniform.csv", "outside"]),
    ("file-escapes", _entry(lambda e: e["sets"]["uniform"].update(file="../../x.csv")), ["file", "outside"]),
    ("file-absolute", _entry(lambda e: e["sets"]["uniform"].update(file="/etc/passwd")), ["file", "outside"]),
    ("file-not-text", _entry(lambda e: e["sets"]["uniform"].update(file=7)), ["sets.uniform.file"]),
    ("manifest-list", _manifest(lambda m: []), ["manifest.json", "JSON mapping"]),
    ("manifest-not-json", lambda s: (s / "manifest.json").write_text("{not json"), ["manifest.json", "not valid JSON"]),
    ("manifest-nan", lambda s: (s / "manifest.json").write_text('{"problems": NaN}'), ["manifest.json", "NaN"]),
    ("manifest-problems-list", _manifest(lambda m: {**m, "problems": []}), ["problems", "mapping"]),
    ("manifest-no-mechanism", _entry(lambda e: e.pop("mechanism")), ["problems.mao2017-3rps.mechanism", "missing"]),
    ("manifest-sets-list", _entry(lambda e: e.update(sets=[])), ["problems.mao2017-3rps.sets", "mapping"]),
    ("manifest-no-sha", _entry(lambda e: e["sets"]["uniform"].pop("sha256")), ["sets.uniform.sha256", "64"]),
    ("manifest-no-set", _entry(lambda e: e["sets"].pop("uniform")), ["has no set 'uniform'"]),
    ("manifest-unknowns", _entry(lambda e: e.update(unknowns="alpha")), ["unknowns", "list"]),
    ("manifest-poses-text", _entry(lambda e: e["sets"]["uniform"].update(poses="20")), ["poses", "integer"]),
    ("manifest-huge", lambda s: (s / "manifest.json").write_bytes(b" " * (2 << 20)), ["manifest.json", "larger than"]),
]


@pytest.mark.parametrize("case", POSESET_CASES, ids=[c[0] for c in POSESET_CASES])
def test_pose_set_inputs_are_one_line(case, tmp_path, cli):
    ident, spoil, fragments = case
    path = mini_suite(tmp_path / "s")
    (tmp_path / "s" / "elsewhere.csv").write_text((SUITES / "kinbench-v1" / "mao2017-3rps" / "uniform.csv").read_text())
    spoil(tmp_path / "s" / MINI_SETS)
    line = refused(cli, ["suite", path, "--out", tmp_path / "out", "-q"], tmp_path, *fragments)
    assert "<script>" not in line and "root:" not in line       # no file content quoted
    assert not (tmp_path / "out").exists() or not any(p.is_file() for p in (tmp_path / "out").rglob("*"))


def test_a_swapped_released_set_with_a_resigned_manifest_is_refused(tmp_path, cli):
    path = mini_suite(tmp_path / "s", sets_folder="kinbench-v1")
    # the copy trimmed the manifest: a re-signed released version, as an attacker would make it
    line = refused(cli, ["suite", path, "--out", tmp_path / "out", "-q"], tmp_path, "released kinbench-v1")
    assert "new version" in line or "differs from released" in line
    # the committed release itself loads (its manifest is the released one, byte for byte)
    from fkopt.kinbench.config import load_suite
    from fkopt.kinbench.posesets import load_pose_sets
    assert load_pose_sets(load_suite(SUITES / "kinbench.yaml"))[1]["version"] == "kinbench-v1"


def test_a_mini_suite_of_a_private_version_still_validates(tmp_path):
    from fkopt.run.pipeline import load_any, validate_any
    path = mini_suite(tmp_path / "s")
    assert validate_any(load_any(path), str(path)) == 1


# -- outside results: CSV and IOH (findings 1, 4 and 5) ---------------------------------------------
GOOD_CSV = "problem,set,pose,run,evaluations,best_so_far\n" + "".join(
    f"mao2017-3rps,uniform,{p},0,{e},{f}\n" for p in (0, 1) for e, f in ((1, 5.0), (6, 1e-12)))
GOOD_DAT = "evaluations raw_y\n1 5.0\n6 1e-12\n" * 2
SECRET = "root:x:0:0:SECRET-TOKEN"


def ioh_folder(root: Path, index=None, dat=GOOD_DAT) -> Path:
    """An IOHprofiler folder of one algorithm with both poses of the mini suite."""
    folder = root / "ioh"
    (folder / "run" / "data_f1").mkdir(parents=True, exist_ok=True)
    index = index if index is not None else {
        "algorithm": {"name": "RS"}, "function_name": "mao2017-3rps__uniform",
        "scenarios": [{"path": "data_f1/IOHprofiler_f1_DIM3.dat", "runs": [{"instance": 1}, {"instance": 2}]}]}
    (folder / "run" / "IOHprofiler_f1.json").write_text(index if isinstance(index, str) else json.dumps(index))
    (folder / "run" / "data_f1" / "IOHprofiler_f1_DIM3.dat").write_text(dat)
    return folder


def _index(**change):
    data = {"algorithm": {"name": "RS"}, "function_name": "mao2017-3rps__uniform",
            "scenarios": [{"path": "data_f1/IOHprofiler_f1_DIM3.dat", "runs": [{"instance": 1}, {"instance": 2}]}]}
    data.update(change)
    return data


def _runs(*instances):
    return _index(scenarios=[{"path": "data_f1/IOHprofiler_f1_DIM3.dat", "runs": [{"instance": i} for i in instances]}])


def _path(p):
    return _index(scenarios=[{"path": p, "runs": [{"instance": 1}, {"instance": 2}]}])


def _write_csv(text):
    return lambda root: (root / "x.csv").write_text(text)


def _gzip_bomb(root):
    with _gzip.open(root / "x.csv.gz", "wb", compresslevel=1) as fh:
        fh.write(GOOD_CSV.encode())
        chunk = b"0" * (1 << 20)
        for _ in range(65):
            fh.write(chunk)


def _sparse(root):
    with open(root / "x.csv", "wb") as fh:
        fh.truncate(65 << 20)         # a size past the cap, without writing 65 MB


OUTSIDE_CASES = [   # (id, make the input under root, outside entry, fragments)
    ("csv-gzip-bomb", _gzip_bomb, {"file": "x.csv.gz"}, ["outside[0].file", "x.csv.gz", "unpacks to more than"]),
    ("csv-too-large", _sparse, {"file": "x.csv"}, ["outside[0].file", "larger than"]),
    ("csv-fifo", lambda root: os.mkfifo(root / "x.csv"), {"file": "x.csv"}, ["outside[0].file", "FIFO"]),
    ("csv-dev-zero", lambda root: (root / "x.csv").symlink_to("/dev/zero"), {"file": "x.csv"},
     ["outside[0].file", "character device"]),
    ("csv-folder", lambda root: (root / "x.csv").mkdir(), {"file": "x.csv"}, ["outside[0].file", "a folder"]),
    ("csv-evaluations-1e300", _write_csv(GOOD_CSV.replace(",6,", ",1e300,")), {"file": "x.csv"},
     ["column 'evaluations'", "[0, 2^53]"]),
    ("csv-evaluations-2e53", _write_csv(GOOD_CSV.replace(",6,", f",{2**53 + 2},")), {"file": "x.csv"},
     ["column 'evaluations'", "[0, 2^53]"]),
    ("csv-run-1e300", _write_csv(GOOD_CSV.replace(",0,6,", ",1e300,6,")), {"file": "x.csv"}, ["column 'run'"]),
    ("csv-empty", _write_csv(""), {"file": "x.csv"}, ["outside[0].file", "unreadable CSV"]),
    ("ioh-no-header", lambda root: ioh_folder(root, dat="1 5.0\n6 1e-12\n"), {"ioh": "ioh"},
     ["IOHprofiler_f1_DIM3.dat", "line 1", "header"]),
    ("ioh-dat-text", lambda root: ioh_folder(root, dat=f"evaluations raw_y\n1 {SECRET}\n"), {"ioh": "ioh"},
     ["line 2", "two numbers"]),
    ("ioh-dat-1e300", lambda root: ioh_folder(root, dat="evaluations raw_y\n1e300 5\n" * 2), {"ioh": "ioh"},
     ["evaluations", "[0, 2^53]"]),
    ("ioh-instance-text", lambda root: ioh_folder(root, _runs("x", 2)), {"ioh": "ioh"},
     ["scenarios[0].runs[0].instance", "integer >= 1"]),
    ("ioh-instance-null", lambda root: ioh_folder(root, _runs(None, 2)), {"ioh": "ioh"},
     ["scenarios[0].runs[0].instance"]),
    ("ioh-instance-bool", lambda root: ioh_folder(root, _runs(True, 2)), {"ioh": "ioh"}, ["instance"]),
    ("ioh-function-number", lambda root: ioh_folder(root, _index(function_name=7)), {"ioh": "ioh"},
     ["function_name", "must be text"]),
    ("ioh-mixed-function-names", lambda root: (ioh_folder(root), (root / "ioh" / "run2").mkdir(),
                                               (root / "ioh" / "run2" / "IOHprofiler_f2.json").write_text(
                                                   json.dumps(_index(function_name=2)))),
     {"ioh": "ioh"}, ["IOHprofiler_f2.json", "function_name"]),
    ("ioh-no-algorithm", lambda root: ioh_folder(root, _index(algorithm="RS")), {"ioh": "ioh"}, ["algorithm.name"]),
    ("ioh-scenarios-map", lambda root: ioh_folder(root, _index(scenarios={})), {"ioh": "ioh"}, ["'scenarios'"]),
    ("ioh-index-list", lambda root: ioh_folder(root, "[]"), {"ioh": "ioh"}, ["IOHprofiler_f1.json", "mapping"]),
    ("ioh-index-infinity", lambda root: ioh_folder(root, '{"algorithm": Infinity}'), {"ioh": "ioh"},
     ["IOHprofiler_f1.json", "Infinity"]),
    ("ioh-index-deep", lambda root: ioh_folder(root, "[" * 100_000 + "]" * 100_000), {"ioh": "ioh"},
     ["IOHprofiler_f1.json"]),
    ("ioh-path-dotdot", lambda root: ioh_folder(root, _path("../../secret.dat")), {"ioh": "ioh"},
     ["scenarios[0].path", "outside"]),
    ("ioh-path-absolute", lambda root: ioh_folder(root, _path(str(root / "secret.dat"))), {"ioh": "ioh"},
     ["scenarios[0].path", "outside"]),
    ("ioh-path-etc", lambda root: ioh_folder(root, _path("/etc/passwd")), {"ioh": "ioh"},
     ["scenarios[0].path", "outside"]),
    ("ioh-path-fifo", lambda root: (ioh_folder(root), (root / "ioh" / "run" / "p").mkdir(),
                                    os.mkfifo(root / "ioh" / "run" / "p" / "f.dat"),
                                    ioh_folder(root, _path("p/f.dat"))), {"ioh": "ioh"}, ["FIFO"]),
    ("ioh-path-number", lambda root: ioh_folder(root, _path(5)), {"ioh": "ioh"}, ["scenarios[0].path"]),
    ("ioh-stray-link-outside", lambda root: (ioh_folder(root), (root / "ioh" / "run" / "notes.txt").symlink_to(
        root / "secret.dat")), {"ioh": "ioh"}, ["notes.txt", "outside"]),
    ("ioh-run-folder-link", lambda root: (ioh_folder(root / "elsewhere"), (root / "ioh").mkdir(),
                                          (root / "ioh" / "run").symlink_to(root / "elsewhere" / "ioh" / "run")),
     {"ioh": "ioh"}, ["outside"]),
]


@pytest.mark.parametrize("case", OUTSIDE_CASES, ids=[c[0] for c in OUTSIDE_CASES])
def test_outside_inputs_are_one_line(case, tmp_path, cli):
    ident, make, entry, fragments = case
    root = tmp_path / "s"
    root.mkdir()
    (root / "secret.dat").write_text(f"evaluations raw_y\n{SECRET} 1\n")
    make(root)
    path = mini_suite(root, outside=[{"solver": "ext", "track": "black-box", **entry}])
    line = refused(cli, ["suite", path, "--out", tmp_path / "out", "-q"], tmp_path, *fragments)
    assert "SECRET" not in line                              # never a token of a file it reached
    assert not (tmp_path / "out").exists() or not any(p.is_file() for p in (tmp_path / "out").rglob("*"))


def test_good_outside_csv_gz_and_ioh_still_validate(tmp_path):
    """The checks above refuse only what is wrong: the same mini suite with well-formed files loads."""
    from fkopt.run.pipeline import load_any, validate_any
    from fkopt.kinbench.outside import logged_runs
    from fkopt.kinbench.runner import instances_of
    from fkopt.kinbench.posesets import load_pose_sets
    root = tmp_path / "s"
    root.mkdir()
    with _gzip.open(root / "x.csv.gz", "wt") as fh:
        fh.write(GOOD_CSV)
    ioh_folder(root)
    path = mini_suite(root, outside=[{"solver": "ext", "track": "black-box", "file": "x.csv.gz"},
                                     {"solver": "ioh", "track": "black-box", "ioh": "ioh"}])
    cfg = load_any(path)
    assert validate_any(cfg, str(path)) == 1
    instances = instances_of(cfg, load_pose_sets(cfg)[0])
    for k in (0, 1):
        runs = list(logged_runs(cfg, k, instances))
        assert [(r[2], list(r[4]), list(r[5])) for r in runs] == [(p, [1.0, 6.0], [5.0, 1e-12]) for p in (0, 1)]


# -- --resume: task records checked against the plan, even with a forged digest (finding 2) ------
def _forge_task(tmp_path, edit):
    """The mini suite's one task, computed, edited by ``edit`` and kept as a task file of an
    interrupted run with its digest re-signed in the manifest (what an attacker can do)."""
    from fkopt.run.pipeline import load_any
    from fkopt.kinbench.kind import work_folder
    from fkopt.kinbench.runner import solve_task, suite_plan
    path = mini_suite(tmp_path / "s")
    cfg = load_any(path)
    plan = suite_plan(cfg, str(path))
    rec = json.loads(json.dumps(solve_task(plan.tasks[0].payload)))
    edit(rec)
    work = work_folder(tmp_path / "out", cfg)
    (work / "tasks").mkdir(parents=True)
    task = work / "tasks" / f"{plan.tasks[0].id}.json"
    task.write_text(json.dumps(rec))
    (work / "tasks" / "manifest.json").write_text(json.dumps(
        {"fingerprint": plan.fingerprint, "tasks": {plan.tasks[0].id: hashlib.sha256(task.read_bytes()).hexdigest()}}))
    return path, task


def _row(col, value, i=0):
    return lambda rec: rec["rows"][col].__setitem__(i, value)


RECORD_EDITS = [
    ("fitness-text", _row("fitness", "x"), ["rows.fitness", "not numbers"]),
    ("fitness-nan", _row("fitness", float("nan")), ["rows.fitness"]),
    ("fitness-negative", _row("fitness", -1.0), ["rows.fitness"]),
    ("solver-relabelled", lambda r: r["rows"].update(solver=["pso"] * len(r["rows"]["solver"])),
     ["rows.solver", "'pso'", "'lm'"]),
    ("problem-renamed", _row("problem", "wu2015-3ppr"), ["rows.problem"]),
    ("set-renamed", _row("set", "boundary"), ["rows.set"]),
    ("pose-moved", _row("pose", 7), ["rows.pose"]),
    ("pose-text", _row("pose", "0"), ["rows.pose"]),
    ("run-renumbered", _row("run", 3), ["rows.run"]),
    ("track-changed", _row("track", "exact"), ["rows.track"]),
    ("evaluations-1e300", _row("evaluations", 1e300), ["rows.evaluations"]),
    ("evaluations-past-budget", _row("evaluations", 10_000.0), ["rows.evaluations"]),
    ("target-text", _row("evals_to_1e-02", "soon"), ["rows.evals_to_1e-02"]),
    ("rows-short", lambda r: [v.pop() for v in r["rows"].values()], ["rows", "run rows"]),
    ("rows-column-missing", lambda r: r["rows"].pop("fitness"), ["rows", "columns"]),
    ("rows-column-extra", lambda r: r["rows"].update(extra=[0] * 2), ["rows", "columns"]),
    ("dim-text", lambda r: r.update(dim="3"), ["dim"]),
    ("trace-row-outside", lambda r: r["trace"]["row"].__setitem__(0, 99), ["trace.row"]),
    ("trace-ragged", lambda r: r["trace"]["row"].pop(), ["trace", "length"]),
    ("trace-fitness-text", lambda r: r["trace"]["best_fitness"].__setitem__(0, "x"), ["trace.best_fitness"]),
    ("solves-changed", lambda r: r.update(solves=99), ["solves"]),
    ("wall-negative", lambda r: r.update(wall_s=-1), ["wall_s"]),
]


@pytest.mark.parametrize("case", RECORD_EDITS, ids=[c[0] for c in RECORD_EDITS])
def test_resume_checks_suite_records_against_the_plan(case, tmp_path, cli):
    ident, edit, fragments = case
    path, task = _forge_task(tmp_path, edit)
    line = refused(cli, ["suite", path, "--out", tmp_path / "out", "-q", "--resume"], tmp_path,
                   task.name, "not a finished task of this run", *fragments)
    assert "--resume" in line or "delete it" in line
    assert not (tmp_path / "out" / "kinbench" / "mini").exists()        # nothing published


def test_resume_reuses_an_untouched_suite_record(tmp_path, cli):
    """The check above refuses only edits: the genuine record is reused and published."""
    path, task = _forge_task(tmp_path, lambda rec: None)
    code, _, err = cli("suite", path, "--out", tmp_path / "out", "-q", "--resume")
    assert code == 0, err
    runs = (tmp_path / "out" / "kinbench" / "mini" / "runs.csv").read_text()
    assert runs.count("\n") == 3 and ",lm," in runs


# -- stored results read back by check: regular files inside the folder only (finding 9) --------
@pytest.mark.parametrize("how", ["link-outside", "link-dev-zero", "fifo", "link-inside"])
def test_check_refuses_a_runs_csv_that_is_not_a_regular_file_of_the_folder(finished_study, cli, how):
    cfg, out, final, outside = finished_study
    runs = final / "runs.csv"
    (outside / "runs.csv").write_bytes(runs.read_bytes())     # the same bytes: only the link is wrong
    if how == "link-inside":
        (final / "copy.csv").write_bytes(runs.read_bytes())
    runs.unlink()
    if how == "fifo":
        os.mkfifo(runs)
    else:
        runs.symlink_to({"link-outside": outside / "runs.csv", "link-dev-zero": Path("/dev/zero"),
                         "link-inside": final / "copy.csv"}[how])
    code, _, err = cli("check", out, "-q")                     # returns at once: nothing read through it
    assert code == 1 and "Traceback" not in err, err
    assert "runs.csv" in err and ("symbolic link" in err or "FIFO" in err)
    assert err.strip().splitlines()[-1].startswith("fkopt: check failed:")


# -- huge finite numbers and deep chains in URDF and on the command line (findings 6 and 9) -------
def urdf_chain(n=2, *, axis="0 0 1", xyz="0 0 0.1", rpy="0 0 0", lower="-1", upper="1", mimic=False,
               multiplier="1") -> str:
    s = ['<robot name="r">'] + [f'<link name="l{i}"/>' for i in range(n + 1)]
    for i in range(n):
        m = f'<mimic joint="j{i - 1}" multiplier="{multiplier}"/>' if mimic and i > 0 else ""
        s.append(f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
                 f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/><limit lower="{lower}" upper="{upper}"/>'
                 f'{m}</joint>')
    return "\n".join(s + ["</robot>"])


def _urdf(text):
    return lambda root: (root / "arm.urdf").write_text(text)


URDF_CASES = [   # (id, make root/arm.urdf, fragments)
    ("axis-1e308", _urdf(urdf_chain(axis="0 0 1e308")), ["arm.urdf", "joint 'j0' axis", "|v| <= 1e+09"]),
    ("origin-1e308", _urdf(urdf_chain(xyz="1e308 0 0")), ["origin xyz", "|v| <= 1e+09"]),
    ("origin-negative-huge", _urdf(urdf_chain(xyz="0 -2e9 0")), ["origin xyz", "|v| <= 1e+09"]),
    ("rpy-1e10", _urdf(urdf_chain(rpy="0 1e10 0")), ["origin rpy", "|v| <= 1e+09"]),
    ("limit-1e300", _urdf(urdf_chain(lower="-1e300")), ["limit lower", "|v| <= 1e+09"]),
    ("limit-reversed", _urdf(urdf_chain(lower="1", upper="-1")), ["joint 'j0' <limit>", "lower 1 > upper -1",
                                                                  "needs lower <= upper"]),
    ("mimic-multiplier-huge", _urdf(urdf_chain(3, mimic=True, multiplier="1e300")), ["multiplier", "|v| <= 1e+09"]),
    ("mimic-product-overflow", _urdf(urdf_chain(40, mimic=True, multiplier="1e8")), ["chain of mimics", "1e+09"]),
    ("mimic-3000-deep", _urdf(urdf_chain(3000, mimic=True)), ["arm.urdf", "3000 joints", "at most 1000"]),
    ("chain-2000", _urdf(urdf_chain(2000)), ["arm.urdf", "2000 joints", "at most 1000", "geometry.tip"]),
    ("fifo", lambda root: os.mkfifo(root / "arm.urdf"), ["arm.urdf", "FIFO", "only regular files"]),
    ("dev-zero", lambda root: (root / "arm.urdf").symlink_to("/dev/zero"), ["arm.urdf", "character device"]),
    ("folder", lambda root: (root / "arm.urdf").mkdir(), ["arm.urdf", "a folder"]),
    ("too-large", lambda root: open(root / "arm.urdf", "wb").truncate(5 << 20), ["arm.urdf", "larger than the 4 MB"]),
]


@pytest.mark.parametrize("command", ["fk", "ik"])
@pytest.mark.parametrize("case", URDF_CASES, ids=[c[0] for c in URDF_CASES])
def test_urdf_inputs_are_one_line(case, command, tmp_path, cli):
    ident, make, fragments = case
    make(tmp_path)
    geometry = tmp_path / "g.yaml"
    geometry.write_text(f"file: {tmp_path / 'arm.urdf'}\n")
    argv = (["fk", "urdf", "--geometry", geometry, "--joints", "j0=0.1"] if command == "fk" else
            ["ik", "urdf", "--geometry", geometry, "--pose", "x=0,y=0,z=0.2,alpha=0,beta=0,gamma=0"])
    line = refused(cli, argv, tmp_path, *fragments)
    assert "e+308" not in line.split("bound")[-1]          # never a result printed from such a number


def test_a_500_deep_mimic_chain_and_numbers_within_the_bound_still_work(tmp_path, cli):
    """No recursion in following mimics, and |v| <= 1e9 is accepted: the refusals above are bounds."""
    (tmp_path / "arm.urdf").write_text(urdf_chain(500, mimic=True, xyz="0 0 1e-3", lower="-1e9", upper="1e9"))
    geometry = tmp_path / "g.yaml"
    geometry.write_text(f"file: {tmp_path / 'arm.urdf'}\n")
    code, out, err = cli("fk", "urdf", "--geometry", geometry, "--joints", "j0=0", "--json")
    assert code == 0, err
    assert json.loads(out)["pose"]["z"] == pytest.approx(0.5)


@pytest.mark.parametrize("argv, fragments", [
    (["fk", "3-rps", "--joints", "d1=1e300,d2=1e300,d3=1e300", "--all-solutions"], ["--joints", "'d1'", "1e+09"]),
    (["fk", "3-rps", "--joints", "d1=600,d2=600,d3=-1e300"], ["--joints", "'d3'", "1e+09"]),
    (["ik", "3-rps", "--pose", "alpha=0,beta=1e200,z=600"], ["--pose", "'beta'", "1e+09"]),
    (["fk", "6-sps", "--joints", ",".join(f"l{i}=1e300" for i in range(1, 7))], ["--joints", "1e+09"]),
], ids=["3rps-all-solutions", "3rps-negative", "ik-pose", "6sps"])
def test_huge_command_line_values_are_one_line(argv, fragments, tmp_path, cli):
    refused(cli, argv, tmp_path, *fragments)


def test_within_the_bound_no_solution_stays_exit_1(cli):
    code, _, err = cli("fk", "3-rps", "--joints", "d1=1e8,d2=1e8,d3=1e8")
    assert code == 1 and "no pose" in err and "Traceback" not in err


# -- names on disk are collision-free (finding 7) ---------------------------------------------------
def _crafted(name, sep="-"):
    """The stem a hash suffix would give ``name``: an attacker's label spelled as it."""
    import re as _re
    return _re.sub(r"[^A-Za-z0-9_.-]+", sep, name).strip(sep) + sep + hashlib.sha256(name.encode()).hexdigest()[:8]


@pytest.mark.parametrize("names", [
    ["pso+lm", "pso-lm", "pso lm", "pso--lm", _crafted("pso+lm"), "PSO-LM", "pso/lm", "../pso-lm", ".pso-lm"],
    ["a b", "a_b", "a__b", "a\nb", "a\x1b[31mb", "A_B", "all", "ALL", "", "x", "\u00e9", "\u00e8"],
], ids=["labels", "classes"])
def test_two_distinct_names_never_share_a_file(names, tmp_path):
    from fkopt.files import file_names
    for allowed, sep in (("A-Za-z0-9_.-", "-"), ("A-Za-z0-9_.+-", "_")):
        stems = file_names(names, reserved=("all",), allowed=allowed, sep=sep)
        assert set(stems) == set(names)
        assert len({s.lower() for s in stems.values()}) == len(names)          # also case-insensitively
        assert "all" not in {s.lower() for s in stems.values()}
        for s in stems.values():           # each a file in the folder, none hidden or outside it
            assert s and not s.startswith(".") and "/" not in s and (tmp_path / s).resolve().parent == tmp_path
            (tmp_path / f"{s}.txt").write_text(s)
        assert len(list(tmp_path.glob("*.txt"))) == len(names)
        for p in tmp_path.glob("*.txt"):
            p.unlink()
    assert file_names(["pso-lm", "abc"]) == {"pso-lm": "pso-lm", "abc": "abc"}    # safe names keep themselves


def test_export_keeps_pso_plus_lm_and_an_outside_pso_minus_lm_apart(tmp_path, cli):
    root = tmp_path / "s"
    root.mkdir()
    (root / "x.csv").write_text(GOOD_CSV)
    path = mini_suite(root, solvers=[{"name": "pso+lm"}], outside=[{"solver": "pso-lm", "track": "black-box",
                                                                     "file": "x.csv"}])
    assert cli("suite", path, "--out", tmp_path / "out", "-q")[0] == 0
    code, _, err = cli("export", tmp_path / "out", "--format", "ioh", "--out", tmp_path / "ioh")
    assert code == 0, err
    indexes = sorted((tmp_path / "ioh").glob("*/IOHprofiler_f*.json"))
    names = {json.loads(p.read_text())["algorithm"]["name"]: p.parent.name for p in indexes}
    assert set(names) == {"pso+lm", "pso-lm"} and len(set(names.values())) == 2 and len(indexes) == 2
    assert names["pso-lm"] == "pso-lm"


def test_export_writes_one_folder_per_label(tmp_path):
    """The fast form of the test above: the export's writer, two functions, colliding labels."""
    import numpy as np
    from fkopt.run.iohformat import Function, algorithm_folders, write_function
    runs = [(1, np.array([1, 6]), np.array([5.0, 1e-12]), [0.0])]
    fns = [Function(name=f"p{i}__uniform", dim=1, instances=["0"], attributes=[],
                    algorithms={"pso+lm": ({}, runs), "pso-lm": ({}, runs), "pso lm": ({}, runs)}) for i in (1, 2)]
    folders = algorithm_folders(label for fn in fns for label in fn.algorithms)
    for fid, fn in enumerate(fns, start=1):
        write_function(tmp_path, fid, fn, folders)
    indexes = sorted(tmp_path.glob("*/IOHprofiler_f*.json"))
    by_folder = {}
    for p in indexes:
        by_folder.setdefault(p.parent.name, set()).add(json.loads(p.read_text())["algorithm"]["name"])
    assert len(indexes) == 6 and len(by_folder) == 3 and all(len(v) == 1 for v in by_folder.values())


def test_every_problem_class_gets_its_own_figure(tmp_path):
    from types import SimpleNamespace
    import pandas as pd
    from fkopt.kinbench.reports import ecdf_figures
    scopes = ["all", "class:all", "class:a b", "class:a_b"]
    df = pd.DataFrame([{"scope": s, "solver": "lm", "track": "jacobian", "evals_per_dim": 2.0, "reached": 1,
                        "pairs": 1, "fraction": 1.0} for s in scopes])
    sr = SimpleNamespace(config=SimpleNamespace(targets=[1e-2], budget_per_dim=50, name="mini", subsets=[]),
                         record=pd.DataFrame({"class": []}))
    names = ecdf_figures(sr, tmp_path, {"ecdf.csv": df})
    pngs = sorted(p.name for p in tmp_path.glob("*.png"))
    assert len(pngs) == len(scopes) and "ecdf_all.png" in pngs and "ecdf_a_b.png" in pngs
    assert len([n for n in names if n.endswith(".png")]) == len(scopes)


# -- strict JSON and escaped Markdown (finding 8) ---------------------------------------------------
def _strict_loads(text):
    def refuse(name):
        raise ValueError(f"{name} is not strict JSON")
    return json.loads(text, parse_constant=refuse)


def test_strict_json_writes_null_and_names_every_non_finite_number():
    import numpy as np
    from fkopt.files import strict_json
    data = {"pose": {"x": float("inf"), "y": np.float64("nan"), "z": 1.5}, "error": -np.inf,
            "solutions": [{"x": [1.0, float("nan")]}], "n": np.int64(3), "ok": np.bool_(True)}
    out = _strict_loads(strict_json(data))
    assert out["pose"] == {"x": None, "y": None, "z": 1.5} and out["error"] is None and out["n"] == 3
    assert out["non_finite"] == {"pose.x": "inf", "pose.y": "nan", "error": "-inf", "solutions[0].x[1]": "nan"}
    assert "non_finite" not in _strict_loads(strict_json({"a": 1.0}))       # only when there is one


@pytest.mark.parametrize("argv", [["ik", "3-rps", "--pose", "alpha=0,beta=0,z=600", "--json"],
                                  ["fk", "3-rps", "--joints", "d1=598.85,d2=671.92,d3=629.16", "--json"]],
                         ids=["ik", "fk"])
def test_json_outputs_are_strict_even_when_a_number_is_not_finite(argv, cli, monkeypatch):
    import numpy as np
    from fkopt.mechanisms.rps3 import ThreeRPS
    real = ThreeRPS.ik
    if argv[0] == "ik":      # an answer holding inf and NaN (as a broken plug-in could return)
        monkeypatch.setattr(ThreeRPS, "ik", lambda self, pose: np.array([np.inf, np.nan, 600.0]))
    code, out, err = cli(*argv)
    data = _strict_loads(out.strip().splitlines()[0])          # a strict parser accepts it
    if argv[0] == "ik":
        assert data["joints"]["d1"] is None and data["non_finite"] == {"joints.d1": "inf", "joints.d2": "nan"}
    else:
        assert code == 0 and data["solved"] is True and "non_finite" not in data
    monkeypatch.setattr(ThreeRPS, "ik", real)


HOSTILE_TEXT = ["<script>alert(1)</script>", "<img src=x onerror=alert(1)>", "\x1b[31mred\x1b[0m\x07",
                "a\n# injected heading", "a | b | c", "[link](javascript:alert(1))", "![i](http://x/y.png)", "`code`"]


def test_leaderboard_md_escapes_what_it_copies(tmp_path):
    from types import SimpleNamespace
    import pandas as pd
    from markdown_it import MarkdownIt
    from fkopt.kinbench.reports import leaderboard_markdown
    config = SimpleNamespace(title=" ".join(HOSTILE_TEXT), name="mini", pose_sets="my-sets", problems=[1],
                             sets=["uniform"], runs=1, budget_per_dim=50, targets=[1e-2], bootstrap=100, alpha=0.05,
                             subsets=[])
    lb = pd.DataFrame([{"scope": scope, "rank": i + 1, "solver": text, "track": "black-box", "score": 0.5,
                        "ci_low": 0.4, "ci_high": 0.6, "instances": 2, "better_than": text, "success_1e-02": 1.0}
                       for scope in ("overall", f"class:{HOSTILE_TEXT[0]}") for i, text in enumerate(HOSTILE_TEXT)])
    ms = pd.DataFrame([{"problem": HOSTILE_TEXT[1], "set": "uniform", "solver": t, "track": "black-box",
                        "target": 1e-2, "trials": 1, "success_rate": 1.0, "ert": 6.0} for t in HOSTILE_TEXT])
    leaderboard_markdown(SimpleNamespace(config=config, timing=None), tmp_path, {"leaderboard.csv": lb,
                                                                                 "measures.csv": ms})
    text = (tmp_path / "leaderboard.md").read_text()
    assert "\x1b" not in text and "\x07" not in text and "<script" not in text and "<img" not in text
    rendered = MarkdownIt("commonmark").enable("table").render(text)
    assert "<script" not in rendered and "<img" not in rendered and "<a " not in rendered and "<code>" not in rendered
    assert rendered.count("<h1>") == 1                       # the newline did not start a heading
    rows = [ln for ln in text.splitlines() if ln.startswith("| ")]
    assert all(ln.count(" | ") == rows[0].count(" | ") for ln in rows if ln.count(" | ") >= 7)  # no cell split
    assert rendered.count("<tr>") == 2 * (len(HOSTILE_TEXT) + 1) + len(HOSTILE_TEXT) + 1


# -- a full disk names the file; the previous result stays (finding 9) ------------------------------
@pytest.mark.parametrize("victim", ["runs.csv", "meta.json"])
def test_disk_full_names_the_file_and_keeps_the_previous_result(victim, tmp_path, cli, monkeypatch):
    import errno
    import pandas as pd
    import fkopt.run.writers
    cfg = tmp_path / "e.yaml"
    cfg.write_text(with_(BASE, name="full", runs=1, iterations=2))
    out = tmp_path / "out"
    assert cli("run", cfg, "--out", out, "-q")[0] == 0
    before = snapshot(out)

    def full(*args, **kwargs):         # what the kernel says at write(): ENOSPC, no file name
        raise OSError(errno.ENOSPC, "No space left on device")
    if victim == "runs.csv":
        real = pd.DataFrame.to_csv
        monkeypatch.setattr(pd.DataFrame, "to_csv", lambda self, path=None, *a, **k: full() if Path(str(path)).name
                            == victim else real(self, path, *a, **k))
    else:
        monkeypatch.setattr(fkopt.run.writers, "write_json", lambda path, data: full())
    line = one_line_error(cli("run", cfg, "--out", out, "-q"), "No space left on device", "previous result is kept")
    assert f"{out / 'test' / 'full' / victim}: cannot write" in line       # the file as the user knows it
    # the finished tasks stay in the hidden work folder (.full.partial) for --resume; results untouched
    assert {k: v for k, v in snapshot(out).items() if ".full.partial" not in k} == before
    assert not any(".new-" in p.name for p in out.rglob(".*"))


# -- configs and geometry YAML are read bounded too (finding 1) --------------------------------------
def _config_path(how, root):
    f = root / "c.yaml"
    if how == "fifo":
        os.mkfifo(f)
    elif how == "dev-zero":
        f.symlink_to("/dev/zero")
    elif how == "folder":
        f.mkdir()
    elif how == "sparse":
        with open(f, "wb") as fh:
            fh.truncate(2 << 20)
    return f


CONFIG_READS = [("fifo", "FIFO"), ("dev-zero", "character device"), ("folder", "a folder"), ("sparse", "larger than")]


@pytest.mark.parametrize("how, fragment", CONFIG_READS, ids=[c[0] for c in CONFIG_READS])
@pytest.mark.parametrize("command", ["run", "suite", "geometry"])
def test_config_and_geometry_files_that_are_not_regular_files_are_one_line(command, how, fragment, tmp_path, cli):
    f = _config_path(how, tmp_path)
    argv = {"run": ["run", f, "--out", tmp_path / "out"], "suite": ["suite", f, "--out", tmp_path / "out"],
            "geometry": ["ik", "3-rps", "--pose", "alpha=0,beta=0,z=600", "--geometry", f]}[command]
    refused(cli, argv, tmp_path, "c.yaml", fragment)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("budget", [1, 50], ids=["no-answer-within-budget", "answers"])
def test_genuine_suite_records_of_every_track_pass_the_resume_check(budget, tmp_path):
    """The check refuses only what the plan would not produce: every track's own records pass,
    also a run with no answer within its budget (fitness inf, evaluations = budget)."""
    from fkopt.run.pipeline import load_any
    from fkopt.kinbench.runner import record_problem, solve_task, suite_plan
    path = mini_suite(tmp_path / "s", solvers=[{"name": "lm"}, {"name": "forward"}, {"name": "pso"},
                                               {"name": "gabc+lm"}], budget_per_dim=budget)
    plan = suite_plan(load_any(path), str(path))
    for task in plan.tasks:
        rec = json.loads(json.dumps(solve_task(task.payload)))        # as a task file holds it
        assert record_problem(task, rec) is None, task.label
        if budget == 1:
            assert rec["rows"]["fitness"][0] == float("inf")


def test_a_ctrl_c_inside_a_task_store_write_never_leaves_a_file_its_manifest_does_not_name(tmp_path, monkeypatch):
    """The race a real SIGINT hit in CI: the task file was in place and the manifest not yet
    rewritten, so --resume refused the file as "changed since fkopt wrote it". The manifest now
    names the digest first: interrupted there, no file appears and --resume recomputes the task."""
    from types import SimpleNamespace
    from fkopt.run.tasks import TaskStore
    out = tmp_path / "out"
    store = TaskStore(out, out / ".x.partial", out / "x", "x", {}, "fp")
    store.open(None, resume=False)
    store.add("t0", {"fingerprint": "fp", "value": 1})
    calls = []

    def interrupted():
        calls.append(1)
        raise KeyboardInterrupt
    monkeypatch.setattr(store, "_write_manifest", interrupted)
    with pytest.raises(KeyboardInterrupt):
        store.add("t1", {"fingerprint": "fp", "value": 2})
    assert calls and not (store.tasks / "t1.json").exists()
    again = TaskStore(out, out / ".x.partial", out / "x", "x", {}, "fp")
    plan = SimpleNamespace(tasks=[SimpleNamespace(id="t0"), SimpleNamespace(id="t1")], check=None)
    assert list(again.open(plan, resume=True)) == ["t0"]
