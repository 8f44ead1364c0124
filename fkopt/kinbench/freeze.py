"""The commands that make a kinbench version's frozen data (run once per version, then commit):

    python -m fkopt.kinbench.freeze pose-sets SUITE.yaml [POSES [MEASURE]]  # its pose-set folder
    python -m fkopt.kinbench.freeze robots configs/suites/robots             # the arms' copies (v3's)
    python -m fkopt.kinbench.freeze release SUITE.yaml                       # its entry of RELEASES

``pose-sets``: :func:`fkopt.kinbench.posesets.write_pose_sets` into the folder the suite's
``pose_sets`` names (v1, v2: 20 poses, near-singular by ``condition``; v3: ``100 sigma``).
``robots``: :func:`fkopt.kinbench.robots.write_robots`. ``release``: the table entry of
:data:`fkopt.kinbench.releases.RELEASES` for the suite's version, to paste in when it is released.
(One module on top of the others, so the modules a suite's config loads import no config.)
"""
from __future__ import annotations

import sys
from pathlib import Path

USAGE = ("usage: python -m fkopt.kinbench.freeze pose-sets SUITE.yaml [POSES [condition|sigma]] | "
         "robots FOLDER | release SUITE.yaml")


def main(argv: list[str]) -> int:
    from fkopt.errors import FkoptError
    try:
        if len(argv) >= 2 and argv[0] == "pose-sets":
            from fkopt.kinbench.config import load_suite
            from fkopt.kinbench.posesets import pose_set_folder, write_pose_sets
            cfg = load_suite(argv[1])
            extra = [int(argv[2])] + argv[3:4] if len(argv) > 2 else []
            print(write_pose_sets(cfg, pose_set_folder(cfg), *extra))
        elif len(argv) == 2 and argv[0] == "robots":
            from fkopt.kinbench.robots import write_robots
            for path in write_robots(Path(argv[1])):
                print(path)
        elif len(argv) == 2 and argv[0] == "release":
            from fkopt.problems import FITNESS_VERSION
            from fkopt.kinbench.config import load_suite
            from fkopt.kinbench.releases import release_files
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
