"""Records tests/inverse_bits/one_pose.json: one-pose ``fkopt.inverse`` answers (joints as the
hex of their float64 bytes, restarts, evaluations), for tests/test_inverse_solver.py to hold the
solver and ``inverse`` to: ``PYTHONPATH=<checkout> python tests/inverse_bits/record.py OUT``.
First recorded with the code before ``fkopt.InverseSolver`` (commit 255c592). Every arm was
re-recorded on 6 Dec 2026 (issue 38, fifth round) with the code that changed ``inverse``'s
defaults (damping 0.01 -> 5e-4, the stall test at 0.5, iterations 10 -> 20: every answer moved; the recording
platform is platform.json's). The history below is that of the earlier recordings.

``python tests/inverse_bits/record.py OUT ARM...`` records only those arms into an existing OUT.
The URDF and MJCF arms (``urdf``, ``mjcf``, ``panda``) were re-recorded so on 6 Dec 2026 with the
code of commit 64ae05b, on the recording platform (platform.json): issue 41 moved URDF and MJCF
joint limits inward (never outward, by at most 1.3e-10 deg), which moved those answers by at most
2.8e-10 deg with the same restarts, evaluations and verdicts; the other arms keep 255c592's bits."""
import json
import sys
import tempfile

import numpy as np

import fkopt
from fkopt.mechanisms.urdf import example_robot, example_robots_folder

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from cases import arms, calls  # noqa: E402

only = set(sys.argv[2:])
out = {}
if only:
    with open(sys.argv[1]) as f:
        out = json.load(f)
tmp = tempfile.mkdtemp()
for name, arm in arms(fkopt, example_robot, example_robots_folder, mjcf_file=f"{tmp}/anchored.xml"):
    if only and name not in only:
        continue
    rows = []
    for target, kw in calls(arm, name):
        r = fkopt.inverse(arm, target, **kw)
        rows.append({"joints": np.asarray(r.joints, dtype=float).tobytes().hex(), "restarts": int(r.restarts),
                     "evaluations": int(r.evaluations["jacobian"]), "solved": bool(r.solved)})
    out[name] = rows
with open(sys.argv[1], "w") as f:
    json.dump(out, f, indent=0)
