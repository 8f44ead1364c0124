"""Read access to a results tree ``RESULTS/<paper>/<experiment>/``."""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import pandas as pd

from fkopt import registry
from fkopt.errors import FkoptError
from fkopt.files import parse_json, read_stored, read_stored_csv


@dataclass
class Experiment:
    folder: Path

    @property
    def name(self) -> str:
        return self.folder.name

    @property
    def paper(self) -> str:
        return self.folder.parent.name

    @cached_property
    def meta(self) -> dict:
        if not (self.folder / "meta.json").exists():
            raise FileNotFoundError(self.folder / "meta.json")
        data = parse_json(read_stored(self.folder, "meta.json"), "meta.json")
        if not isinstance(data, dict) or not isinstance(data.get("config"), dict):
            raise ValueError("no 'config' mapping")
        return data

    def meta_error(self) -> str | None:
        """Why meta.json cannot be used (missing, unreadable, not JSON, no config), or None."""
        try:
            self.meta
        except FileNotFoundError:
            return "missing"
        except FkoptError as err:
            return f"unreadable ({str(err)[:120]})"
        except (OSError, UnicodeDecodeError, ValueError) as err:
            return f"unreadable ({type(err).__name__}: {str(err)[:80]})"
        return None

    @property
    def config(self) -> dict:
        return self.meta["config"]

    @property
    def title(self) -> str:
        return self.meta.get("title") or self.name

    def has(self, name: str) -> bool:
        return (self.folder / name).exists()

    def table(self, name: str) -> pd.DataFrame:
        """A CSV of the experiment by stem (``summary``) or file name."""
        file = name if name.endswith((".csv", ".csv.gz")) else f"{name}.csv"
        if not (self.folder / file).exists() and (self.folder / f"{file}.gz").exists():
            file += ".gz"      # trace.csv.gz (fkopt.run.trace)
        # bounded: inside the folder, a regular file, a gzip bomb one line, not the memory
        return read_stored_csv(self.folder, file, keep_default_na=True)

    def figures(self) -> list[str]:
        return sorted(p.name for p in self.folder.glob("*.png"))

    def row(self, table: str, **where) -> pd.Series:
        df = self.table(table)
        for k, v in where.items():
            df = df[df[k] == v]
        if len(df) != 1:
            raise KeyError(f"{self.paper}/{self.name} {table}: {len(df)} rows match {where}")
        return df.iloc[0]


class Store:
    def __init__(self, root: str | Path):
        self.root = Path(root)

    def experiments(self, paper: str | None = None) -> list[Experiment]:
        pattern = f"{paper}/*/meta.json" if paper else "*/*/meta.json"
        # hidden folders (.<name>.new-*, .<name>.partial: unfinished writes) are not results
        return [Experiment(p.parent) for p in sorted(self.root.glob(pattern))
                if not any(part.startswith(".") for part in p.relative_to(self.root).parts)]

    def get(self, paper: str, name: str) -> Experiment | None:
        folder = self.root / paper / name
        return Experiment(folder) if (folder / "meta.json").exists() else None

    def require_readable(self) -> None:
        """One-line error unless the root is a folder whose results all have a readable meta.json."""
        if not self.root.is_dir():
            raise FkoptError(f"{self.root}: no such results folder")
        exps = self.folders()
        if not exps:
            raise FkoptError(f"{self.root}: no stored results (folders <paper>/<name>/ with meta.json)")
        for e in exps:
            problem = e.meta_error()
            if problem and problem != "missing":
                raise FkoptError(f"{e.folder / 'meta.json'}: {problem}")

    def folders(self, paper: str | None = None) -> list[Experiment]:
        """Every results folder ``<paper>/<name>/`` holding a file, with or without meta.json
        (hidden folders -- unfinished or temporary -- are not results, and a nested results root
        such as ``results/peers`` is a store of its own: ``fkopt check results/peers``)."""
        papers = [self.root / paper] if paper else sorted(p for p in self.root.iterdir() if p.is_dir())
        out = []
        for p in papers:
            if p.name.startswith(".") or not p.is_dir():
                continue
            if not paper and (p / "index.csv").exists():
                continue   # a results root of its own (results/peers: make reproduce-peers), checked on its own
            for f in sorted(p.iterdir()):
                if f.is_dir() and not f.name.startswith(".") and any(x.is_file() for x in f.iterdir()):
                    out.append(Experiment(f))
        return out

    def papers(self) -> list[str]:
        return sorted({e.paper for e in self.experiments()})


def mechanism_of(exp_or_name):
    """The mechanism of a stored experiment (from its recorded config), or a registered name's default."""
    if isinstance(exp_or_name, str):
        return registry.mechanism_class(exp_or_name)()
    m = exp_or_name.config["mechanism"]
    return registry.mechanism_class(m["name"])(bounds=dict(m.get("bounds") or {}), **(m.get("geometry") or {}))


def locate(path: str | Path) -> tuple[Store, str | None, str | None]:
    """``(store, paper, name)`` for a results root, a paper folder or one experiment folder."""
    path = Path(path)
    if (path / "meta.json").exists() or (path / "summary.csv").exists():
        return Store(path.parent.parent), path.parent.name, path.name
    if any(path.glob("*/meta.json")) or any(path.glob("*/summary.csv")):
        return Store(path.parent), path.name, None
    return Store(path), None, None
