"""README stays a first hour's read and every link of README and docs/ resolves."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: Pages other work items write; linked from README before they land (none now).
WRITTEN_ELSEWHERE: set[str] = set()


def test_readme_fits_on_a_few_screens_and_starts_with_the_two_commands():
    lines = (ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 250
    block = lines[lines.index("```bash") + 1:lines.index("```")]
    assert block[0].startswith('python3 -m venv .venv && .venv/bin/pip install -e ".[test]" -c constraints.txt '
                               '&& .venv/bin/fkopt reproduce')
    assert block[1].startswith(".venv/bin/python -m pytest")
    assert "min" in block[0] and "min" in block[1]          # expected durations


def test_every_relative_link_resolves():
    broken = []
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", page.read_text(encoding="utf-8")):
            if "://" in target:
                continue
            path = (page.parent / target).resolve()
            if not path.exists() and str(path.relative_to(ROOT)) not in WRITTEN_ELSEWHERE:
                broken.append(f"{page.relative_to(ROOT)} -> {target}")
    assert not broken, broken


def test_readme_python_api_block_runs():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    code = text.split("## Python API")[1].split("```python\n")[1].split("```")[0]
    names: dict = {}
    exec(compile(code, "README.md (Python API)", "exec"), names)
    assert bool(names["fk"].solved) and bool(names["inv"].solved) and names["result"].success.all()


def test_readme_quotes_the_stored_kinbench_leaderboard():
    """README's kinbench scores are those of the stored leaderboard (rerun make bench-suite, then update)."""
    import pandas as pd
    board = pd.read_csv(ROOT / "results" / "kinbench" / "kinbench" / "leaderboard.csv")
    text = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    quoted = {"track:black-box": {"scipy:differential_evolution": "DE", "pso": "PSO", "pabc": "P-ABC", "abc": "ABC",
                                  "gabc": "GABC", "aco": "ACO"},
              "track:jacobian": {"lm": "LM", "dls": "DLS", "pso+lm": "PSO+LM", "gabc+lm": "GABC+LM"}}
    for scope, names in quoted.items():
        rows = board[board["scope"] == scope].sort_values("rank")
        assert list(rows["solver"]) == list(names), scope          # README lists them in rank order
        for solver, score in zip(rows["solver"], rows["score"]):
            assert f"{names[solver]} {score:.3f}" in text, (solver, f"{score:.3f}")


def test_robots_page_advice_is_the_stored_kinbench_v2_board():
    """docs/robots.md's "which solver" table is recomputed from the stored runs.csv and timing.csv."""
    from fkopt.kinbench.advice import advice_markdown, advice_table
    table = advice_markdown(advice_table(ROOT / "results" / "kinbench" / "kinbench-v2"))
    assert table in (ROOT / "docs" / "robots.md").read_text(encoding="utf-8")


def test_mechanism_docs_do_not_contradict_the_robots_page():
    """Issue 32: the mechanisms page said yourdfpy parses URDF, that URDF chains had no analytic
    Jacobian and suggested `w_p: 1000` (which no schema allows); the robots page said otherwise."""
    text = (ROOT / "docs" / "mechanisms-and-algorithms.md").read_text(encoding="utf-8")
    for stale in ("yourdfpy parses", "no analytic Jacobian for URDF", "w_p: 1000"):
        assert stale not in text


def test_readme_quotes_the_stored_v3_robot_board():
    from fkopt.kinbench.advice import fk_sentence, robots_markdown, robots_summary
    folder = ROOT / "results" / "kinbench" / "kinbench-v3-robots"
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert robots_markdown(robots_summary(folder)) in readme
    assert fk_sentence(folder) in readme.splitlines()


def test_kinbench_docs_have_one_row_per_outside_entry_of_the_stored_board():
    """docs/kinbench.md's "Outside entries" table (the package's protocol and figures, kinbench's
    reproduction, the board's settings, the differences and why) names every outside entry of the
    stored per-robot board: its clock rows and its throughput-only entries."""
    import pandas as pd
    folder = ROOT / "results" / "kinbench" / "kinbench-v3-robots"
    board = pd.read_csv(folder / "leaderboard-robots.csv")
    rates = pd.read_csv(folder / "throughput.csv")
    outside = set(board.loc[board["entry"] == "outside", "solver"]) | set(rates.loc[rates["entry"] == "outside", "solver"])
    text = (ROOT / "docs" / "kinbench.md").read_text()
    start = text.index("| entry | the package's own protocol and published numbers |")
    rows = [line for line in text[start:].split("\n\n", 1)[0].splitlines()[2:]]
    first_cells = [row.split(" | ", 1)[0] for row in rows]
    named = {n for cell in first_cells for n in re.findall(r"`([^`]+)`", cell)}
    assert outside and outside <= named, sorted(outside - named)
    assert all(row.count(" | ") == 4 for row in rows)           # five cells each, none left out


def test_citation_names_every_board_version_and_the_stored_boards_match_it():
    """CITATION.cff names every frozen board version (fkopt/kinbench/releases.py BOARDS), and the
    board version each stored per-robot board's meta.json names is among them: a paper cites the
    board it compared against."""
    import json
    import yaml
    from fkopt.kinbench.releases import BOARDS, board_version
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    named = set(cff["keywords"])
    versions = {f"{board}/{v}" for board, vs in BOARDS.items() for v in vs}
    assert versions <= named and all(v in cff["abstract"] for v in versions), sorted(versions - named)
    stored = [json.loads(p.read_text()).get("board_version") for p in (ROOT / "results" / "kinbench").glob("*/meta.json")]
    stored = {v for v in stored if v}
    assert stored and stored <= versions, sorted(stored - versions)
    assert all(board_version(board) in cff["message"] for board in BOARDS)      # the latest of each
