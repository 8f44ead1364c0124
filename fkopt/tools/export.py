"""Export stored results for other tools: ``fkopt export RESULTS --format ioh --out DIR``.

``ioh``: the files that the ``ioh`` package's ``ioh.logger.Analyzer`` writes (IOHexperimenter;
what IOHanalyzer and iohinspector load), built from each experiment or suite folder's
``meta.json``, ``runs.csv`` and ``trace.csv.gz`` (:mod:`fkopt.run.trace`,
:mod:`fkopt.kinbench.traces`) -- no rerun. Every folder becomes IOH *functions*
(:class:`fkopt.run.iohformat.Function`) by its kind's loader (``Kind.ioh_functions``: an
experiment's in :mod:`fkopt.kinds.experiment.ioh_functions`, a suite's in
:mod:`fkopt.kinbench.traces`; a study or an assembly search has none), and one writer
(:func:`fkopt.run.iohformat.write_function`) writes them; mapping:

* one **algorithm** folder per algorithm label (an experiment's) or solver label (a suite's,
  outside solvers included): ``DIR/<label>/``;
* **functions**: an experiment is one, named ``<paper>_<name>``, with one **instance** per case
  (case index + 1); a suite is one per problem, named by the problem, with one instance per
  (set, pose) in the suite's set order, then pose order (from 1). The instance labels are the
  experiment attribute ``instances`` (``1=<case>``; ``1=<set>/<pose>``). ``function_id``
  numbers the functions from 1 over the exported folders (sorted by path) and, within a
  suite, its problems in the suite's order -- so a suite exported alone has function_id =
  problem order;
* the **dimension** is the number of unknowns, each **run** one IOH run (per instance in the
  order of the run ids);
* ``DIR/<label>/IOHprofiler_f<id>_<name>.json`` is the index, with the keys and layout of the
  Analyzer's (``version``, ``suite``, ``function_id``, ``function_name``, ``maximization``,
  ``algorithm``, ``experiment_attributes``, ``attributes``, ``scenarios`` with per run
  ``instance``, ``evals``, ``best``), and ``DIR/<label>/data_f<id>_<name>/IOHprofiler_f<id>_DIM<dim>.dat``
  the data: a header line ``evaluations raw_y`` opens each run, then one line per improvement of
  the best-so-far fitness at its exact evaluation number -- the first line is evaluation 1, as
  IOH readers split runs there -- and a last line at the run's final evaluation count (its
  best-so-far fitness) when the last improvement came earlier. A suite's run that had no
  fitness value yet writes ``inf`` in the ``.dat`` and a ``null`` best ``y`` in the index
  (strict JSON has no infinity).

``version`` is the ``ioh`` release whose Analyzer output this layout was compared with
(:data:`fkopt.run.iohformat.IOH_VERSION`); fkopt's version is in ``algorithm.info`` and in the manifest
``DIR/fkopt-export.txt``. The manifest (which folders were exported, and the mark that lets a
later export replace ``DIR``) is not a ``.json`` or ``.info`` file, so IOH readers, which load
every ``**/*.json``, never mistake it for an index. The folder is written atomically, after every
input file has been read and checked, and only over a folder that ``fkopt export`` wrote before.
"""
from __future__ import annotations

from pathlib import Path

import fkopt
import fkopt.kinbench  # noqa: F401  (registers every kind, and with it each kind's loader of IOH functions)
from fkopt.errors import FkoptError
from fkopt.files import output_folder, parse_json, read_stored, short_token, write_atomically
from fkopt.run.iohformat import ATTRIBUTES, IOH_VERSION, Function, algorithm_folders, write_function
from fkopt.run.kinds import stored_kind

__all__ = ["FORMATS", "MARKER", "ATTRIBUTES", "IOH_VERSION", "experiment_folders", "check_out", "ioh_export"]

FORMATS = ("ioh",)
MARKER = "fkopt-export.txt"
#: Marks of folders written by earlier fkopt releases (replaced like MARKER's).
OLD_MARKERS = ("fkopt-export.json",)


def experiment_folders(results: Path) -> list[Path]:
    """Result folders (experiments, suites, ...) under ``results``: the folder itself, or
    ``*/meta.json``, ``*/*/meta.json``."""
    results = Path(results)
    if not results.is_dir():
        raise FkoptError(f"{results}: not a results folder (no such directory)")
    if (results / "meta.json").is_file():
        return [results]
    found = sorted({p.parent for pat in ("*/meta.json", "*/*/meta.json") for p in results.glob(pat)})
    if not found:
        raise FkoptError(f"{results}: no experiment or suite results (no meta.json in it or its subfolders)")
    return found


def check_out(out: Path, results: Path) -> Path:
    """Refuse an --out that would overwrite stored results or an unrelated folder."""
    out, res = Path(out).resolve(), Path(results).resolve()
    if out == res or res in out.parents or out in res.parents:
        raise FkoptError(f"--out {out}: must lie outside the results folder {res} (and not contain it)")
    if out.exists() and not out.is_dir():
        raise FkoptError(f"--out {out}: exists and is not a folder")
    if out.is_dir() and any(out.iterdir()) and not any((out / m).is_file() for m in (MARKER,) + OLD_MARKERS):
        raise FkoptError(f"--out {out}: folder exists and was not written by fkopt export; choose a new folder")
    return out


def _meta(folder: Path) -> dict:
    path = folder / "meta.json"
    try:
        meta = parse_json(read_stored(folder, "meta.json"), str(path))
    except FkoptError as err:
        raise FkoptError(f"{path}: cannot read ({str(err).removeprefix(f'{path}: ')})") from None
    if not isinstance(meta, dict) or not isinstance(meta.get("config"), dict):
        raise FkoptError(f"{path}: no 'config' object (not a meta.json that fkopt wrote)")
    return meta


def _load(folder: Path) -> list[Function] | None:
    """The IOH functions of a results folder, by its kind's loader (``Kind.ioh_functions``):
    None for a kind without one (studies and assembly searches: no per-run traces)."""
    meta = _meta(folder)
    kind = stored_kind(meta)
    if kind is None:
        named = meta.get("kind") or meta["config"].get("kind")
        raise FkoptError(f"{folder / 'meta.json'}: kind '{short_token(named)}' is not one this fkopt knows "
                         "(not a meta.json that it wrote)")
    return None if kind.ioh_functions is None else kind.ioh_functions(folder, meta)


def ioh_export(results: Path, out: Path) -> list[Path]:
    """Write the IOHprofiler files of every experiment and suite under ``results`` into ``out``;
    returns the index files written."""
    folders = experiment_folders(results)
    out = check_out(out, results)
    loaded = [(f, fns) for f in folders if (fns := _load(f)) is not None]
    if not loaded:
        raise FkoptError(f"{results}: only studies/assembly results, which have no per-run traces to export")
    # the shared checks of the output folder (a folder, writable), once the inputs are good
    output_folder(out)

    functions = [fn for _, fns in loaded for fn in fns]
    folders = algorithm_folders(label for fn in functions for label in fn.algorithms)

    def write(tmp: Path) -> None:
        for fid, fn in enumerate(functions, start=1):
            write_function(tmp, fid, fn, folders)
        (tmp / MARKER).write_text("fkopt export (IOHprofiler format; this file is the export's mark, "
                                  "not data)\n" + f"format: ioh\nfkopt: {fkopt.__version__}\nioh layout: {IOH_VERSION}\n"
                                  + "results:\n" + "".join(f"  {f}\n" for f, _ in loaded))

    write_atomically(out, write)
    return sorted(out.glob("*/IOHprofiler_f*.json"))
