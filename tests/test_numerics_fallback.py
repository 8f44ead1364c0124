"""The compiled path where it cannot run (issue 38) and a corrupted or unwritable compiled-code
cache (issue 42, break 14), simulated in child processes: numba made unimportable, numba's
compiler sabotaged, cache files overwritten with garbage or emptied, a cache folder that cannot
exist. Each is one line on stderr at most once per process and the numpy path (or a rebuilt
cache) answers; never a traceback."""
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

# numba and its llvmlite made unimportable, as on a platform without their wheels
NO_NUMBA = "import sys; sys.modules['numba'] = None; sys.modules['llvmlite'] = None\n"
# numba imports but its compiler fails on every kernel
NO_COMPILE = textwrap.dedent("""
    import numba.core.dispatcher as d
    def broken(self, sig):
        raise RuntimeError("LLVM ERROR: sabotaged compiler")
    d.Dispatcher.compile = broken
""")
# two calls of fkopt.inverse (one pose, then a batch) on the DH arm: the reference answers
INVERSE_TWICE = textwrap.dedent("""
    import numpy as np, fkopt
    arm = fkopt.mechanism("7dof-arm")
    q = np.array([10.0, -20.0, 30.0, 40.0, -50.0, 60.0, 5.0])
    a = fkopt.inverse(arm, arm.fk(q), seed=1)
    b = fkopt.inverse(arm, arm.fk(np.stack([q, q * 0.5])), seed=1)
    print(bool(a.solved), bool(b.solved.all()))
""")


def child(code, cache=None, env=None):
    e = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])))
    e.pop("FKOPT_NUMERICS", None)
    if cache is not None:
        e["NUMBA_CACHE_DIR"] = str(cache)
    e.update(env or {})
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=e, timeout=600)


def test_without_numba_one_line_names_numba_and_the_numpy_path_answers():
    proc = child(NO_NUMBA + INVERSE_TWICE)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["True", "True"]
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr                  # once per process, though called twice
    assert lines[0].startswith("fkopt: compiled numerics unavailable") and "pip install numba" in lines[0]
    assert "llvmlite" not in lines[0]                    # the package to install is numba
    # asked for explicitly (FKOPT_NUMERICS=compiled): an FkoptError naming numba
    proc = child(NO_NUMBA + "import fkopt, numpy as np\nfrom fkopt.numerics import path\ntry:\n    path.compiled()\n"
                 "except fkopt.errors.FkoptError as e:\n    print(e)", env={"FKOPT_NUMERICS": "compiled"})
    assert "pip install numba" in proc.stdout and "llvmlite" not in proc.stdout, proc.stdout + proc.stderr
    # and the version line says which path runs
    proc = child(NO_NUMBA + "import sys; from fkopt.cli import main; sys.argv = ['fkopt', '--version']; main()")
    assert "numerics: numpy (numba is not installed" in proc.stdout, proc.stdout + proc.stderr


def test_a_compiler_that_fails_falls_back_with_one_line(tmp_path):
    proc = child(NO_COMPILE + INVERSE_TWICE, cache=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["True", "True"]
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and "numba does not compile here" in lines[0] and "pip install numba" in lines[0], \
        proc.stderr


# compiled kernels that compile in a second or two: the probe and the run streams' refill
CACHED_KERNELS = textwrap.dedent("""
    import numpy as np
    from fkopt.numerics import compiled as c
    gens = [np.random.default_rng(s) for s in range(5)]
    S = c.pcg64_states(gens)
    buf = np.empty((5, 7))
    c.fill_uniforms(buf, 0, S)
    ok = np.array_equal(buf, np.stack([g.random(7) for g in gens]))
    print(c.probe(2.0), ok)
""")


def _cache_files(folder, suffix):
    return sorted(p for p in Path(folder).rglob(f"*{suffix}") if "set-aside" not in str(p.parent))


def test_a_corrupted_cache_file_is_set_aside_with_one_line_and_rebuilt(tmp_path):
    _corrupt_set_aside_rebuilt(tmp_path, ".nbi", b"garbage\n")


@pytest.mark.parametrize("suffix,content", [(".nbi", b""), (".nbc", b"\x80\x04garbage"), (".nbc", b"")],
                         ids=["index-empty", "data-garbage", "data-empty"])
def test_every_kind_of_corrupted_cache_file_is_set_aside_and_rebuilt(tmp_path, suffix, content):
    _corrupt_set_aside_rebuilt(tmp_path, suffix, content)


def _corrupt_set_aside_rebuilt(tmp_path, suffix, content):
    cache = tmp_path / "cache"
    first = child(CACHED_KERNELS, cache=cache)
    assert first.returncode == 0 and first.stdout.split() == ["3.0", "True"], first.stderr
    files = _cache_files(cache, suffix)
    assert len(files) >= 2
    for f in files:                                        # every kernel's file spoiled
        f.write_bytes(content)
    second = child(CACHED_KERNELS, cache=cache)
    assert second.returncode == 0 and second.stdout.split() == ["3.0", "True"], second.stderr
    lines = second.stderr.splitlines()
    assert len(lines) == 1, second.stderr
    assert "held an unreadable file" in lines[0] and "set aside in" in lines[0]
    aside = [p for p in cache.rglob("set-aside-*") if p.is_dir()]
    assert len(aside) == 1 and len(list(aside[0].iterdir())) >= 2 * len(files) // (2 if suffix == ".nbi" else 1)
    # rebuilt: the next process loads the fresh files, silently
    third = child(CACHED_KERNELS, cache=cache)
    assert third.returncode == 0 and third.stdout.split() == ["3.0", "True"] and third.stderr == "", third.stderr
    assert all(f.stat().st_size > 0 for f in _cache_files(cache, suffix))


def test_no_usable_cache_folder_is_one_line_not_a_traceback(tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    # numba's only locator the user-given folder, which cannot exist (a path under a file)
    proc = child(CACHED_KERNELS, cache=blocker / "cache",
                 env={"NUMBA_CACHE_LOCATOR_CLASSES": "_UserProvidedCacheLocator"})
    assert proc.returncode == 0 and proc.stdout.split() == ["3.0", "True"], proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and "no writable folder for numba's compiled-code cache" in lines[0], proc.stderr


def test_a_cache_folder_that_turns_unwritable_costs_only_the_cache(tmp_path):
    """The folder was usable when numba chose it, then a save fails (here: it is replaced by a
    file between the import and the first call)."""
    cache = tmp_path / "cache"
    code = textwrap.dedent(f"""
        import shutil
        from fkopt.numerics import compiled as c
        shutil.rmtree({str(cache)!r}); open({str(cache)!r}, "w").close()
        print(c.probe(2.0))
    """)
    proc = child(code, cache=cache)
    assert proc.returncode == 0 and proc.stdout.split() == ["3.0"], proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and "cannot use numba's compiled-code cache" in lines[0], proc.stderr
