"""The commands that make a kinbench version's frozen data (run once per version, then commit):

    python -m fkopt.kinbench.freeze pose-sets SUITE.yaml [POSES [MEASURE]]  # its pose-set folder
    python -m fkopt.kinbench.freeze robots configs/suites/robots             # the arms' copies (v3's)
    python -m fkopt.kinbench.freeze release SUITE.yaml                       # its entry of RELEASES
    python -m fkopt.kinbench.freeze paths SUITE.yaml [PATHS]                 # its paths track's path set

``pose-sets``: :func:`fkopt.kinbench.posesets.write_pose_sets` into the folder the suite's
``pose_sets`` names (v1, v2: 20 poses, near-singular by ``condition``; v3: ``100 sigma``).
``robots``: :func:`fkopt.kinbench.robots.write_robots`. ``paths``:
:func:`fkopt.kinbench.paths.write_path_set` into the folder ``tracks.paths.path_set`` names (20
paths per arm unless PATHS is given). ``release``: the table entry of
:data:`fkopt.kinbench.releases.RELEASES` for the suite's version, to paste in when it is released.
(One module on top of the others, so the modules a suite's config loads import no config.)
"""
from __future__ import annotations

import sys
from pathlib import Path

from fkopt.errors import FkoptError
from fkopt.files import stored_sha256
from fkopt.kinbench.config import load_suite
from fkopt.kinbench.paths import write_path_set
from fkopt.kinbench.posesets import pose_set_folder, write_pose_sets
from fkopt.kinbench.releases import release_files
from fkopt.kinbench.robots import write_robots
from fkopt.problems import FITNESS_VERSION
from fkopt.run.config_base import files_folder

USAGE = ("usage: python -m fkopt.kinbench.freeze pose-sets SUITE.yaml [POSES [condition|sigma]] | "
         "robots FOLDER | release SUITE.yaml | paths SUITE.yaml [PATHS]")


def main(argv: list[str]) -> int:
    try:
        if len(argv) >= 2 and argv[0] == "pose-sets":
            cfg = load_suite(argv[1])
            extra = [int(argv[2])] + argv[3:4] if len(argv) > 2 else []
            print(write_pose_sets(cfg, pose_set_folder(cfg), *extra))
        elif len(argv) in (2, 3) and argv[0] == "paths":
            cfg = load_suite(argv[1])
            if cfg.tracks is None or cfg.tracks.paths is None:
                raise FkoptError(f"{argv[1]}: tracks.paths: missing; the path set is that track's")
            folder = write_path_set(cfg, files_folder(cfg) / cfg.tracks.paths.path_set,
                                    int(argv[2]) if len(argv) == 3 else 20)
            print(f'    "{folder.name}": Release(fitness={FITNESS_VERSION}, files={{')     # its RELEASES entry
            for path in sorted(folder.iterdir()):
                print(f'        "{folder.name}/{path.name}": "{stored_sha256(path)}",')
            print("    }),")
        elif len(argv) == 2 and argv[0] == "robots":
            for path in write_robots(Path(argv[1])):
                print(path)
        elif len(argv) == 2 and argv[0] == "release":
            cfg = load_suite(argv[1])
            print(f'    "{cfg.pose_sets}": Release(fitness={FITNESS_VERSION}, files={{')
            for name, digest in release_files(cfg).items():
                print(f'        "{name}": "{digest}",')
            print("    }),")
        else:
            print(USAGE, file=sys.stderr)
            return 2
    except (FkoptError, ValueError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
