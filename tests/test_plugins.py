"""Plug-ins: entry points, package.module:Class references (refused unless fkopt subclasses),
the example package installed with pip and run from YAML, ``fkopt list``."""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml

import fkopt
from fkopt import registry
from fkopt.algorithms.base import Algorithm
from fkopt.errors import FkoptError
from fkopt.mechanisms.base import ParallelMechanism
from test_cli import assert_one_line_error

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "plugin"


@pytest.mark.parametrize("name, fragment", [
    ("subprocess:run", "is a function, not a class"),
    ("os:system", "not a class"),
    ("fkopt.errors:did_you_mean", "is a function, not a class"),
    ("fkopt.solve:Result", "does not subclass fkopt.algorithms.base.Algorithm; refused"),
    ("fkopt.mechanisms.rps3:ThreeRPS", "does not subclass fkopt.algorithms.base.Algorithm"),
    ("no_such_pkg.mod:X", "cannot import no_such_pkg.mod (ModuleNotFoundError"),
    ("fkopt.algorithms.abc:NoSuch", "module fkopt.algorithms.abc has no attribute 'NoSuch'"),
    ("nope", "unknown algorithm 'nope'; allowed: abc"),
])
def test_references_are_refused_before_anything_is_called(name, fragment):
    with pytest.raises(FkoptError, match=fragment.replace("(", r"\(")):
        registry.algorithm_class(name)


def test_a_reference_to_a_subclass_is_accepted():
    assert registry.algorithm_class("fkopt.algorithms.abc:ABC").name == "abc"
    assert registry.mechanism_class("fkopt.mechanisms.rps3:ThreeRPS").name == "3-rps"
    with pytest.raises(FkoptError, match="reserved for algorithm adapters"):
        registry.mechanism_class("scipy:differential_evolution")


def test_plugin_classes_missing_required_methods_are_named():
    class NoIterate(Algorithm):
        name = "half"

        def initialize(self, problem, population, streams, x0=None):
            raise AssertionError("never called")

    class NoIk(ParallelMechanism):
        name = "no-ik"

    with pytest.raises(FkoptError, match="algorithm plug-in 'x:Half'.*is missing iterate"):
        registry.check_class(NoIterate, "algorithm", "x:Half")
    with pytest.raises(FkoptError, match="mechanism plug-in 'x:NoIk'.*is missing ik"):
        registry.check_class(NoIk, "mechanism", "x:NoIk")


def test_config_naming_a_function_is_one_line_error(tmp_path, fkopt_run):
    cfg = {"name": "evil", "mechanism": {"name": "3-rps"}, "cases": [{"pose": {"alpha": 9, "beta": 13, "z": 622}}],
           "algorithms": [{"name": "subprocess:run", "params": {"args": ["touch", str(tmp_path / "pwned")]}}],
           "runs": 1, "iterations": 2}
    path = tmp_path / "evil.yaml"
    path.write_text(yaml.safe_dump(cfg))
    proc = fkopt_run("run", str(path), "--out", str(tmp_path / "out"))
    assert_one_line_error(proc, "subprocess:run", "not a class")
    assert proc.returncode == 2
    assert not (tmp_path / "pwned").exists() and not (tmp_path / "out").exists()


def test_list_shows_origins_and_a_mechanism_in_detail(fkopt_run):
    out = json.loads(fkopt_run("list", "--json").stdout)
    assert out["origins"]["mechanisms"]["3-rps"] == "built-in"
    assert out["origins"]["algorithms"]["scipy:differential_evolution"].startswith("adapter (scipy")
    detail = json.loads(fkopt_run("list", "6-sps-cmm", "--json").stdout)
    assert detail["bounds"]["z"] == [0.7, 1.1] and detail["bounds_units"]["z"] == "m"
    assert detail["pose"]["alpha"] == "deg" and list(detail["joints"]) == [f"l{i}" for i in range(1, 7)]
    assert detail["geometry"]["Rb"] == 0.5 and detail["from"] == "built-in"
    text = fkopt_run("list", "6-sps-cmm").stdout
    for fragment in ("x [m]", "alpha [deg]", "l1 [m]", "0.7", "1.1", "Rb", "default geometry"):
        assert fragment in text, fragment
    assert_one_line_error(fkopt_run("list", "no-such-mech"), "unknown mechanism 'no-such-mech'")


@pytest.fixture(scope="module")
def installed_example(tmp_path_factory):
    """The example package installed by pip from its local path, without network, into a
    target folder that only the subprocesses of these tests put on their path."""
    from importlib.metadata import version
    from importlib.util import find_spec
    major, minor = (int(v) for v in version("setuptools").split(".")[:2])
    if (major, minor) < (70, 1) and find_spec("wheel") is None:   # the test extra installs >= 70.1
        pytest.skip("building the example offline needs setuptools >= 70.1 or wheel: pip install -e '.[test]'")
    tmp = tmp_path_factory.mktemp("plugin")
    src = tmp / "src"
    shutil.copytree(EXAMPLE, src, ignore=shutil.ignore_patterns("build", "*.egg-info"))
    target = tmp / "site"
    proc = subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-index", "--no-deps",
                           "--no-build-isolation", "--target", str(target), str(src)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert (target / "fkopt_example").is_dir()
    assert any(target.glob("fkopt_example_plugin-*.dist-info/entry_points.txt"))
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), str(target), env.get("PYTHONPATH", "")])
    return env


def run_cli(env, *args, cwd=None):
    return subprocess.run([sys.executable, "-m", "fkopt.cli", *args], capture_output=True, text=True,
                          env=env, cwd=cwd, timeout=600)


def test_example_plugin_found_through_entry_points(installed_example, fkopt_run):
    out = json.loads(run_cli(installed_example, "list", "--json").stdout)
    assert out["origins"]["mechanisms"]["five-bar"] == "entry point (fkopt-example-plugin 0.1.0)"
    assert out["origins"]["algorithms"]["de"] == "entry point (fkopt-example-plugin 0.1.0)"
    detail = json.loads(run_cli(installed_example, "list", "five-bar", "--json").stdout)
    assert detail["bounds"] == {"x": [-80.0, 80.0], "y": [80.0, 200.0]} and detail["joints"]["theta1"] == "deg"
    # without the package on the path the names are unknown again (nothing is built in)
    assert "five-bar" not in json.loads(fkopt_run("list", "--json").stdout)["mechanisms"]


def test_example_plugin_runs_from_yaml_end_to_end(installed_example, tmp_path):
    cfg = yaml.safe_load((EXAMPLE / "five_bar_de.yaml").read_text())
    cfg.update(runs=3, iterations=150)
    cfg["algorithms"] = [a for a in cfg["algorithms"] if a["name"] in ("de", "gabc")]
    cfg["algorithms"][1]["iterations"] = 75
    path = tmp_path / "five_bar.yaml"
    path.write_text(yaml.safe_dump(cfg))
    proc = run_cli(installed_example, "run", str(path), "--out", str(tmp_path / "out"), "-q")
    assert proc.returncode == 0, proc.stderr
    folder = tmp_path / "out" / "experiments" / "five_bar_de"
    summary = pd.read_csv(folder / "summary.csv")
    assert set(summary.algorithm) == {"de", "gabc"}
    de = summary[summary.algorithm == "de"]
    assert (de.mean_evaluations == 10 * 151).all()        # population per generation, + initial
    assert (de.success_rate == 1.0).all()                  # FK of the five-bar found below 1e-10
    runs = pd.read_csv(folder / "runs.csv")
    assert runs[runs.algorithm == "de"].abs_error_x.max() < 1e-3
    meta = json.loads((folder / "meta.json").read_text())
    assert meta["mechanism"]["name"] == "five-bar"


def test_broken_plugin_is_one_line_naming_it(installed_example, tmp_path):
    site = Path(installed_example["PYTHONPATH"].split(os.pathsep)[1])
    broken = tmp_path / "site"
    shutil.copytree(site, broken)
    (broken / "fkopt_example" / "de.py").write_text("import no_such_dependency_xyz\n")
    env = dict(installed_example, PYTHONPATH=os.pathsep.join([str(ROOT), str(broken)]))
    proc = run_cli(env, "fk", "3-rps", "--joints", "d1=600,d2=670,d3=630", "--algorithm", "de")
    assert_one_line_error(proc, "algorithm plug-in 'de'", "fkopt-example-plugin 0.1.0",
                          "ModuleNotFoundError", "no_such_dependency_xyz")


def test_readme_minimal_plugin_example_works(tmp_path, monkeypatch):
    """docs/plugins.md's complete minimal example, named as package.module:Class, solves its FK."""
    text = (ROOT / "docs" / "plugins.md").read_text()
    code = text.split("# mypkg/walk.py\n", 1)[1].split("```", 1)[0]
    (tmp_path / "mypkg").mkdir()
    (tmp_path / "mypkg" / "__init__.py").write_text("")
    (tmp_path / "mypkg" / "walk.py").write_text(code)
    monkeypatch.syspath_prepend(str(tmp_path))
    m = fkopt.mechanism("mypkg.walk:Slider")
    problem = fkopt.fk_problem(m, m.ik([40.0, 60.0]))
    r = fkopt.solve(problem, "mypkg.walk:Walk", population=10, iterations=300, runs=2, seed=1,
                    params={"step": 0.05})
    assert r.algorithm == "walk" and r.evaluations.tolist() == [3010, 3010]
    assert abs(r.x[r.best_run] - [40.0, 60.0]).max() < 0.5


def test_built_in_names_never_read_entry_points(monkeypatch):
    def boom(kind):
        raise AssertionError("entry points scanned")
    monkeypatch.setattr(registry, "entry_points", boom)
    assert registry.mechanism_class("3-rps").name == "3-rps"
    assert registry.algorithm_class("gabc").name == "gabc"
    assert registry.algorithm_class("scipy:dual_annealing").name == "scipy:dual_annealing"
