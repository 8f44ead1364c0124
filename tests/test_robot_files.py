"""Robot files nobody here wrote, each read with the file that showed a bug (issue 41): dexmate's
Vega-1 arm (package dexmate-urdf) and airo-models' UR3e (package airo-models), both test
dependencies installed from PyPI."""
import math
from importlib.resources import files

import numpy as np
import pytest

import fkopt
from fkopt.errors import FkoptError

VEGA_1 = files("dexmate_urdf") / "robots" / "humanoid" / "vega_1" / "vega_1.urdf"
UR3E = files("airo_models") / "arms" / "ur3e" / "ur3e.urdf"


@pytest.mark.parametrize("side", ["L", "R"])
def test_vega_1_arm_bounds_never_lie_outside_the_files_limits(side):
    """Its limits (-3.071 rad, ...) are no whole degrees: rounding them in degrees to the nearest
    9th decimal moved -3.071 rad to -3.071000000005658 rad, so an exact answer at the bound
    failed a strict check against the file by 5.7e-12 rad. Every bound, converted as every check
    converts it (deg * pi/180), must be within the file's limits."""
    arm = fkopt.mechanism("urdf", file=str(VEGA_1), base="arm_center", tip=f"{side}_ee")
    assert len(arm.joint_names) == 7
    for (lo, hi), joint in zip(arm.bounds.tolist(), arm.chain_joints):
        file_lo, file_hi = joint["limits"]
        assert file_lo <= lo * (math.pi / 180.0) and hi * (math.pi / 180.0) <= file_hi, joint["name"]
        # and inward by no more than the rounding: the arm keeps its range
        assert lo * (math.pi / 180.0) - file_lo < 1e-11 and file_hi - hi * (math.pi / 180.0) < 1e-11
    internal = arm.bounds * arm._to_si[:, None]           # what the field adapters hand to solvers
    limits = np.array([j["limits"] for j in arm.chain_joints])
    assert (internal[:, 0] >= limits[:, 0]).all() and (internal[:, 1] <= limits[:, 1]).all()


def test_whole_degree_limits_still_read_as_whole_degrees(tmp_path):
    """pi rad reads as 180 deg (the rounding kept where it moves a bound inward or not at all)."""
    text = ('<robot name="r"><link name="a"/><link name="b"/>'
            '<joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
            f'<limit lower="{-math.pi!r}" upper="{math.pi / 2!r}"/></joint></robot>')
    (tmp_path / "r.urdf").write_text(text)
    arm = fkopt.mechanism("urdf", file=str(tmp_path / "r.urdf"))
    lo, hi = arm.bounds[0]
    assert lo * (math.pi / 180.0) >= -math.pi and hi * (math.pi / 180.0) <= math.pi / 2
    assert abs(lo + 180.0) < 1e-12 and abs(hi - 90.0) < 1e-12


def test_ur3e_with_an_undeclared_drake_prefix_is_read_like_pinocchio_reads_it(capsys):
    """airo-models' UR3e writes <limit drake:acceleration=...> without declaring the prefix;
    the XML parser refused the whole file ("unbound prefix"). Read it as pinocchio and yourdfpy
    do: one warning line, the prefixed attributes ignored, the kinematics the file's."""
    import pinocchio as pin
    from fkopt.mechanisms import urdf as urdf_module
    urdf_module._WARNED.clear()
    arm = fkopt.mechanism("urdf", file=str(UR3E), tip="tool0")
    fkopt.mechanism("urdf", file=str(UR3E), tip="tool0")
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "fkopt: warning:" in err and "'drake:'" in err and "ur3e.urdf" in err
    assert arm.joint_names == ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
                               "wrist_2_joint", "wrist_3_joint")
    assert arm.bounds[2].tolist() == [-180.0, 180.0]
    model = pin.buildModelFromUrdf(str(UR3E))
    data = model.createData()
    rng = np.random.default_rng(41)
    for q_deg in rng.uniform(-170, 170, size=(5, 6)):
        pin.forwardKinematics(model, data, np.radians(q_deg))
        pin.updateFramePlacements(model, data)
        expected = data.oMf[model.getFrameId("tool0")].homogeneous
        assert np.abs(np.asarray(arm.fk_matrix(q_deg)).reshape(4, 4) - expected).max() < 1e-12


def test_a_prefix_that_is_not_the_problem_still_fails_with_one_line(tmp_path):
    """Only unbound prefixes are forgiven: other malformed XML is still one line naming the file."""
    (tmp_path / "bad.urdf").write_text('<robot name="r"><link name="a"/><joint name="j"></robot>')
    with pytest.raises(FkoptError, match=r"bad\.urdf: malformed URDF"):
        fkopt.mechanism("urdf", file=str(tmp_path / "bad.urdf"))
