"""kinbench: a benchmark suite of kinematics problems x frozen pose sets x solvers x runs.

``kind: suite`` config files (:mod:`.config`), frozen versioned pose sets with checksums
(:mod:`.posesets`), the suite runner on the experiment layer's one solve path (:mod:`.runner`),
COCO-style measures and bootstrap rankings (:mod:`.measures`), and the leaderboard files
(:mod:`.reports`, :mod:`.html`). See docs/kinbench.md.
"""
# Importing kinbench registers every built-in kind of config with the engine (fkopt.run.kinds):
# the three of fkopt.kinds, then kinbench's own suite kind.
import fkopt.kinds  # noqa: E402,F401
from fkopt.kinbench import kind  # noqa: E402,F401
