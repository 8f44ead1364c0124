"""``fkopt list``: the mechanisms and algorithms fkopt knows, by kind (``--long``: pose, joints,
parameters and where each comes from), or one mechanism's geometry, bounds, units and names."""
from __future__ import annotations

import json
import re
import textwrap
from pathlib import Path
from typing import Optional

import typer

from fkopt import registry
from fkopt.cli.arguments import mechanism_from_options
from fkopt.cli.entry_point import app, console
from fkopt.errors import FkoptError
from fkopt.files import strict_json


@app.command("list")
def list_cmd(mech: Optional[str] = typer.Argument(None, help="a mechanism: show its geometry, bounds, "
                                                              "units, pose and joint names"),
             geometry: Optional[Path] = typer.Option(None, "--geometry", help="YAML file of geometry "
                                                     "overrides (for urdf also the .urdf file itself)"),
             as_json: bool = typer.Option(False, "--json", help="print one JSON object instead of "
                                          "tables: {mechanisms, algorithms, origins}, or with MECH its "
                                          "geometry, bounds, units and names"),
             long: bool = typer.Option(False, "--long", "-l", help="the full tables: each mechanism's pose, "
                                       "joints and paper, each algorithm's parameters with their defaults, "
                                       "and where each comes from")):
    """List the mechanisms and algorithms fkopt knows: their names by kind (--long: pose, joints,
    parameters and where each comes from)."""
    if mech is not None:
        return _list_mechanism(mech, as_json, geometry)
    if geometry is not None:
        raise FkoptError("--geometry: name the mechanism it is for (fkopt list MECH --geometry FILE)")
    mechs, algos = registry.entries("mechanism"), registry.entries("algorithm")
    if as_json:
        typer.echo(strict_json({"mechanisms": [e.name for e in mechs], "algorithms": [e.name for e in algos],
                               "origins": {"mechanisms": {e.name: e.origin for e in mechs},
                                           "algorithms": {e.name: e.origin for e in algos}}}))
        return
    if not long:
        return _list_names(mechs, algos)
    from rich import box                  # rich only where a table is printed (start-up)
    from rich.markup import escape
    from rich.table import Table
    # fits 80 columns: one line per unit group in a cell, borders only under the header
    table = Table(title="mechanisms (fkopt list MECH for geometry and bounds)", box=box.SIMPLE_HEAD,
                  pad_edge=False)
    for col in ("name", "kind", "pose", "joints", "paper", "from"):
        table.add_column(col, no_wrap=col in ("name", "kind"))
    for e in mechs:
        try:   # class attributes only: listing builds no mechanism (the URDF one reads a file)
            m = registry.mechanism_class(e.name)
        except FkoptError as err:
            table.add_row(e.name, "", "", "", "", escape(f"{e.origin}; error: {err}"))
            continue
        mark = "*" if m.reconstruction else ""
        table.add_row(e.name, m.kind, escape(unit_groups(m.pose_names, m.pose_units)),
                      escape(unit_groups(m.joint_names, m.joint_units)), (m.paper or "") + mark, escape(e.origin))
    con = console()
    con.print(table)
    con.print("* a reconstruction: the paper does not print the whole model (docs/models.md)")
    table = Table(title="algorithms", box=box.SIMPLE_HEAD, pad_edge=False)
    for col in ("name", "parameters (defaults)", "from"):
        table.add_column(col)
    for e in algos:
        if e.origin.startswith("adapter"):
            table.add_row(e.name, "params: passed to the library; evaluations, workers", e.origin)
            continue
        try:
            cls = registry.algorithm_class(e.name)
        except FkoptError as err:
            table.add_row(e.name, escape(f"error: {err}"), e.origin)
            continue
        params = ", ".join(f"{k}={f.default!r}" for k, f in cls.Params.model_fields.items())
        table.add_row(e.name, escape(params), e.origin)
    con.print(table)
    typer.echo("Also: any package.module:Class subclassing fkopt's Mechanism or Algorithm\n"
               "(see docs/plugins.md).")


def _list_names(mechs, algos) -> None:
    """``fkopt list`` without --long: the names, one line per kind, to fit a screen."""
    groups: dict[str, list[str]] = {}
    notes = []
    for e in mechs:
        try:   # class attributes only: listing builds no mechanism
            m = registry.mechanism_class(e.name)
        except FkoptError as err:
            notes.append(f"{e.name}: {err}")
            continue
        label = {"parallel": "parallel (fk)", "serial": "serial (ik)"}.get(m.kind, m.kind)
        groups.setdefault(label, []).append(e.name + ("*" if m.reconstruction else ""))
    lines = ["mechanisms (fkopt list MECH: its geometry, bounds, units and names)"]
    lines += _name_lines(groups)
    groups = {}
    for e in algos:
        if e.origin.startswith("adapter"):
            library = e.name.partition(":")[0]
            optional = " (optional)" if "optional" in e.origin else ""
            groups.setdefault(f"{library}{optional}", []).append(e.name)
            continue
        if not e.origin.startswith("built-in"):
            groups.setdefault("plug-ins", []).append(e.name)
            continue
        try:
            cls = registry.algorithm_class(e.name)
        except FkoptError as err:
            notes.append(f"{e.name}: {err}")
            continue
        entry = getattr(registry, "SOLVERS", {}).get(e.name)       # the registry's facts of the solver
        kind = ("exact" if getattr(entry, "track", None) == "exact" else "swarm + local" if "+" in e.name
                else "local" if getattr(cls, "local", False) else "swarm")
        groups.setdefault(kind, []).append(e.name)
    lines += ["algorithms (fkopt list --long: their parameters and defaults)"]
    lines += _name_lines(groups)
    lines.append("* a reconstruction: the paper does not print the whole model (docs/models.md). Also any "
                 "package.module:Class subclassing Mechanism or Algorithm (docs/plugins.md).")
    lines += [f"error: {n}" for n in notes]
    width = 80
    out = []
    for line in lines:
        indent = " " * (line.index(":") + 2) if line.startswith("  ") and ":" in line else "  "
        out += textwrap.wrap(line, width, subsequent_indent=indent, break_on_hyphens=False) or [""]
    typer.echo("\n".join(out))


def _name_lines(groups: dict[str, list[str]]) -> list[str]:
    if not groups:
        return []
    wide = max(len(k) for k in groups) + 1
    return [f"  {(k + ':').ljust(wide)} " + ", ".join(v) for k, v in groups.items()]


def unit_groups(names, units) -> str:
    """Names with their units, one line per run of names sharing a unit, numbered names as a
    range: ``x, y, z [m]`` / ``alpha, beta, gamma [deg]``, ``q1..q7 [deg]``."""
    groups: list[tuple[str, list[str]]] = []
    for name, unit in zip(names, units):
        if groups and groups[-1][0] == unit:
            groups[-1][1].append(name)
        else:
            groups.append((unit, [name]))
    parts = []
    for unit, members in groups:
        numbered = [re.fullmatch(r"([A-Za-z_]+)([0-9]+)", n) for n in members]
        if len(members) > 2 and all(numbered) and len({m.group(1) for m in numbered}) == 1 \
                and [int(m.group(2)) for m in numbered] == list(range(int(numbered[0].group(2)),
                                                                      int(numbered[0].group(2)) + len(members))):
            text = f"{members[0]}..{members[-1]}"
        else:
            text = ", ".join(members)
        parts.append(f"{text} [{unit}]")
    return "\n".join(parts)


def _list_mechanism(name: str, as_json: bool, geometry: Optional[Path] = None) -> None:
    m = mechanism_from_options(name, geometry)
    d = m.describe()
    origin = next((e.origin for e in registry.entries("mechanism") if e.name == name), "direct reference")
    units = dict(zip(m.unknown_names, m.unknown_units))
    if as_json:
        typer.echo(strict_json({**d, "from": origin, "bounds_units": units}))
        return
    from rich.markup import escape        # rich only where a table is printed (start-up)
    from rich.table import Table
    con = console()
    title = f"{name}: {m.kind} mechanism" + (f", {m.paper}" if m.paper else "") + f" ({origin})"
    con.print(f"[bold]{escape(title)}[/]")
    if m.reconstruction:
        con.print(escape(f"reconstruction: {m.reconstruction}"))
    if "chain" in d:
        con.print(escape("chain:  " + ", ".join(f"{k}={v}" for k, v in d["chain"].items())))
    con.print("pose:   " + ", ".join(f"{n} \\[{u}]" for n, u in d["pose"].items()))
    con.print("joints: " + ", ".join(f"{n} \\[{u}]" for n, u in d["joints"].items()))
    bounds = Table(title=f"workspace bounds of the unknowns ({'pose' if m.kind == 'parallel' else 'joints'})")
    for col in ("variable", "lower", "upper", "unit"):
        bounds.add_column(col, justify="right" if col in ("lower", "upper") else "left")
    for n, (lo, hi) in d["bounds"].items():
        bounds.add_row(n, f"{lo:g}", f"{hi:g}", units.get(n, ""))
    con.print(bounds)
    if d.get("chain_joints"):                          # URDF: every moving joint as the file has it
        chain = Table(title="chain joints (URDF units; a mimic joint follows its unknown: "
                            "q = multiplier * unknown + offset)")
        for col in ("joint", "type", "lower", "upper", "unit", "unknown", "multiplier", "offset"):
            chain.add_column(col, justify="right" if col in ("lower", "upper", "multiplier", "offset") else "left")
        for j in d["chain_joints"]:
            lim = j["limits"] or ("-", "-")
            chain.add_row(escape(j["name"]), j["type"], *(f"{v:g}" if v != "-" else v for v in lim), j["unit"],
                          escape(j["unknown"]), f"{j['multiplier']:g}", f"{j['offset']:g}")
        con.print(chain)
    geo = Table(title="default geometry (override with geometry: in YAML or keyword arguments)" if geometry is None
                else f"geometry: the defaults with the values of {geometry}")
    for col in ("key", "value", "description"):
        geo.add_column(col)
    fields = type(m.geometry).model_fields
    for key, value in d["geometry"].items():
        desc = fields[key].description or "" if key in fields else ""
        geo.add_row(key, escape(json.dumps(value, default=str)), escape(desc))
    con.print(geo)
