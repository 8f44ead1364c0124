"""Geometry instances of the parallel mechanisms (fkopt.kinbench.instances): `instances: K` on a suite
problem yields name-i1..name-iK, drawn from the suite's seed inside the documented ranges, each
non-degenerate with its workspace box."""
import numpy as np
import pytest

from fkopt.errors import FkoptError
from fkopt.kinbench.config import suite_from_dict
from fkopt.kinbench.instances import CHECK_POSES, SPREADS

PAPERS = {
    "mao2017-3rps": {"name": "3-rps", "geometry": {"ra": 274, "rb": 158}},
    "wu2015-3ppr": {"name": "3-ppr"},
    "chang2024-3rpupc": {"name": "3-rpupc-ups", "geometry": {"R": 120, "c": 60}},
    "liu2008-6sps": {"name": "6-sps-cmm", "geometry": {"Rb": 0.5, "Rp": 0.225, "tb": 30, "tp": 30, "ls": 0.18}},
    "dietmaier-6sps": {"name": "6-sps"},
}


def suite(problems, seed=2026):
    return suite_from_dict({"kind": "suite", "name": "t", "pose_sets": "t", "seed": seed, "problems": problems,
                            "solvers": [{"name": "lm"}]}, "t.yaml")


def one(name, k=10, **extra):
    return {"name": name, "problem_class": "c", "instances": k, "mechanism": PAPERS[name], **extra}


@pytest.mark.parametrize("name", PAPERS)
def test_instances_are_seeded_inside_the_documented_ranges_and_not_degenerate(name):
    import fkopt
    cfg = suite([one(name)])
    assert [p.name for p in cfg.problems] == [f"{name}-i{k}" for k in range(1, 11)]
    again = suite([one(name)])
    assert [p.mechanism for p in cfg.problems] == [p.mechanism for p in again.problems]
    other = suite([one(name)], seed=1)
    assert all(a.mechanism.geometry != b.mechanism.geometry for a, b in zip(cfg.problems, other.problems))
    mech_name = PAPERS[name]["name"]
    defaults = fkopt.registry.mechanism_class(mech_name).Geometry().model_dump(mode="json")
    paper = {**defaults, **PAPERS[name].get("geometry", {})}
    geometries = [p.mechanism.geometry for p in cfg.problems]
    assert len({repr(g) for g in geometries}) == 10
    for key, (kind, s) in SPREADS[mech_name].items():
        v = np.array([g[key] for g in geometries], dtype=float)
        ref = np.asarray(paper[key], dtype=float)
        if kind == "scale":
            assert np.all(np.abs(v / ref - 1) <= s + 1e-5)
        elif kind == "shift":
            assert np.all(np.abs(v - ref) <= s + 1e-4)
        else:
            assert np.all(np.abs(v - ref) <= s * np.linalg.norm(ref, axis=1).max() + 1e-5)
        assert np.ptp(v, axis=0).max() > 0                  # the draws do vary
    for p in cfg.problems:                                  # each carries its box; IK finite in it
        mech = fkopt.mechanism(p.mechanism.name, bounds=p.mechanism.bounds, **p.mechanism.geometry)
        assert list(p.mechanism.bounds) == list(mech.unknown_names)
        x = mech.bounds[:, 0] + np.random.default_rng(0).random((CHECK_POSES, len(mech.bounds))) * np.diff(mech.bounds).ravel()
        assert np.all(np.isfinite(mech.ik(x)))


def test_instances_survive_the_quick_tier_and_a_dump_and_reload():
    cfg = suite([one("mao2017-3rps", 3), {"name": "wu2015-3ppr", "problem_class": "c", "mechanism": PAPERS["wu2015-3ppr"]}])
    again = suite_from_dict(cfg.model_dump(mode="json"), "dump")
    assert [p.model_dump() for p in again.problems] == [p.model_dump() for p in cfg.problems]
    assert [p.name for p in cfg.problems] == ["mao2017-3rps-i1", "mao2017-3rps-i2", "mao2017-3rps-i3", "wu2015-3ppr"]


def test_refusals_are_one_line(monkeypatch):
    with pytest.raises(FkoptError, match=r"t.yaml: .*mechanism 'urdf' has no geometry instances") as err:
        suite([{"name": "u", "problem_class": "c", "instances": 2, "mechanism": {"name": "urdf"}}])
    assert "\n" not in str(err.value)
    with pytest.raises(FkoptError, match=r"t.yaml: problems\[0\]\.extra: unknown field"):
        suite([one("mao2017-3rps", extra=1)])
    with pytest.raises(FkoptError, match="own workspace box; drop mechanism.bounds"):
        suite([one("mao2017-3rps", mechanism={**PAPERS["mao2017-3rps"], "bounds": {"z": [400, 600]}})])
    import fkopt.kinbench.instances as I
    monkeypatch.setattr(I, "MAX_CENTRE_KAPPA", 0.0)
    with pytest.raises(FkoptError, match="no non-degenerate geometry for instance 1 in 20 draws .last: its residual"):
        suite([one("chang2024-3rpupc", 2)])
