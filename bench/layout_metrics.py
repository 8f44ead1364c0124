"""Layout measures of the fkopt package (docs/design.md, "Measured"): python bench/layout_metrics.py [ROOT]

Counts, over ROOT/fkopt (default: this checkout): files and lines, top-level modules and
packages, files over 800 lines, file names used in more than one folder, "module:function"
wiring strings naming fkopt's own code, imports inside functions (all, and of fkopt's own
modules) and static import circles (../shared/hooks/import-circles.py when present)."""
from __future__ import annotations

import ast
import re
import subprocess
import sys
from collections import Counter
from pathlib import Path

WIRING = re.compile(r"""["']fkopt(\.[A-Za-z_0-9]+)*:[A-Za-z_]+""")


def measure(root: Path) -> dict:
    pkg = root / "fkopt"
    files = sorted(p for p in pkg.rglob("*.py") if "__pycache__" not in p.parts)
    lines = {p: len(p.read_text().splitlines()) for p in files}
    top_modules = [p for p in pkg.glob("*.py") if p.name not in ("__init__.py", "__main__.py")]
    top_packages = [p for p in pkg.iterdir() if p.is_dir() and (p / "__init__.py").exists()]
    names = Counter(p.name for p in files if p.name != "__init__.py")
    inside = inside_own = 0
    wiring = 0
    for p in files:
        text = p.read_text()
        wiring += len(WIRING.findall(text))
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for sub in ast.walk(node):
                    if isinstance(sub, (ast.Import, ast.ImportFrom)):
                        inside += 1
                        mod = sub.module if isinstance(sub, ast.ImportFrom) else sub.names[0].name
                        if (isinstance(sub, ast.ImportFrom) and sub.level) or (mod or "").startswith("fkopt"):
                            inside_own += 1
    hook = root.parent / "shared" / "hooks" / "import-circles.py"
    circles = None
    if hook.exists():
        out = subprocess.run([sys.executable, str(hook), str(root)], capture_output=True, text=True).stdout
        circles = sum(1 for line in out.splitlines() if "import circle" in line)
    return {"files": len(files), "lines": sum(lines.values()), "top_modules": len(top_modules),
            "top_packages": len(top_packages), "over_800": sorted(f"{p.relative_to(root)} ({n})" for p, n in lines.items() if n > 800),
            "same_name_files": sorted(n for n, c in names.items() if c > 1), "wiring_strings": wiring,
            "imports_inside_functions": inside, "of_fkopt_modules": inside_own, "import_circles": circles}


if __name__ == "__main__":
    for key, value in measure(Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()).items():
        print(f"{key}: {value}")
