"""Read access to a results tree ``RESULTS/<paper>/<experiment>/``."""
from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import pandas as pd


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
        return json.loads((self.folder / "meta.json").read_text())

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
        file = name if name.endswith(".csv") else f"{name}.csv"
        return pd.read_csv(self.folder / file, keep_default_na=True)

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
        return [Experiment(p.parent) for p in sorted(self.root.glob(pattern))]

    def get(self, paper: str, name: str) -> Experiment | None:
        folder = self.root / paper / name
        return Experiment(folder) if (folder / "meta.json").exists() else None

    def papers(self) -> list[str]:
        return sorted({e.paper for e in self.experiments()})
