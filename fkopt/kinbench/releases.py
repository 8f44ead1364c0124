"""Released kinbench versions, frozen in the code.

A pose-set folder's ``manifest.json`` holds the SHA-256 of each of its CSV files, so editing a
pose set *and* its manifest entry would pass :func:`fkopt.kinbench.posesets.load_pose_sets` and
still be labelled with the released name. fkopt therefore carries, for every released version,
the SHA-256 of every file the release consists of (:data:`RELEASES`):

* its pose sets: ``manifest.json`` and every CSV of the folder;
* its problem files: the robot descriptions its problems read (``robots/*.urdf``, ``*.xml``);
* ``fitness``: the :data:`fkopt.problems.FITNESS_VERSION` of the fitness definitions it was
  ranked with (a changed fitness is a new kinbench version, said in CHANGES.md).

A suite whose ``pose_sets`` folder -- or whose manifest's ``version`` -- names a released
version is checked against it by :func:`check_release` whenever its pose sets are loaded
(``fkopt suite``, ``fkopt run``, ``fkopt check``): a file changed, missing or added, or a fitness
version other than this fkopt's, is refused with one line naming the file. A changed suite must
name itself a new version (a new ``pose_sets`` folder whose manifest says that new version).

``python -m fkopt.kinbench.freeze release SUITE.yaml`` prints the table entry of a suite's version
(the step of making a release; an entry is never edited afterwards).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from fkopt.errors import FkoptError
from fkopt.files import MAX_INPUT_BYTES, stored_sha256
from fkopt.problems import FITNESS_VERSION


@dataclass(frozen=True)
class Release:
    fitness: int
    #: path relative to the suite file's folder -> SHA-256
    files: dict[str, str] = field(default_factory=dict)


RELEASES: dict[str, Release] = {
    "kinbench-v1": Release(fitness=1, files={
        "kinbench-v1/chang2024-3rpupc/boundary.csv": "fd00a3689e140b1c59190a764c4f584353e4107f1bc75fc480f0ed9fae10701f",
        "kinbench-v1/chang2024-3rpupc/near-singular.csv": "6b51c9750eb129f423bdf0b544694bdc25c80976afc23d41632d041da4ec6551",
        "kinbench-v1/chang2024-3rpupc/printed.csv": "451c7302a371ec63c2d48f653a8c58c7968898120313b32982b3a202202d6b9b",
        "kinbench-v1/chang2024-3rpupc/uniform.csv": "e981713a2ac9591ea18eed177351dccd7f7f50d5c234d81f1e1da879a409fe63",
        "kinbench-v1/liu2008-6sps/boundary.csv": "717d56b7395f21417bffc9ea6de61bb100822e56c11880706ac5bb580020c176",
        "kinbench-v1/liu2008-6sps/near-singular.csv": "680ab9a00e5bd3972b38e0f6aa35d3bb61f50990c35697dd5f27b9f3b1706371",
        "kinbench-v1/liu2008-6sps/printed.csv": "b6269d8a976c729a1666ac31dcbdadf01096f5cbb5ca27666742c237200b91a0",
        "kinbench-v1/liu2008-6sps/uniform.csv": "22e33b443cc8205613d19bd7d2fad9b95ef4ba68aac077198b820be985198194",
        "kinbench-v1/manifest.json": "0adfdeabdd40e9d37697e67ae5a06bbe861793823ed51bac68c15a2f41daa46a",
        "kinbench-v1/mao2017-3rps/boundary.csv": "2d4b32250e135ae24732759fd14db8b51b5f7f2bfce435ef3d821795582c79ac",
        "kinbench-v1/mao2017-3rps/near-singular.csv": "54fef577662f8f7ab058359201d74583c1f67592ab1c31593c0f6c81749307b5",
        "kinbench-v1/mao2017-3rps/printed.csv": "0939d3cc3902fbb5e434486b25aa6b87514614541c5ef08e858fbdc2690de675",
        "kinbench-v1/mao2017-3rps/uniform.csv": "a6e288f2317a1fc24110cb542796a37725abd6dbb447128b321ba5310027acef",
        "kinbench-v1/wang2020-7dof/boundary.csv": "2b165cd1267849a7e83faa0adf731e111e62d379acae7996ea5a3ca6ef70df2a",
        "kinbench-v1/wang2020-7dof/near-singular.csv": "74d297ec9d36f4fdeb6f04cddf866653108fcf87872c204ce69c3ef4bb486923",
        "kinbench-v1/wang2020-7dof/printed.csv": "a3debf7e8247f002fbc8aa6f22a6264f36e3ed68b1c6a7caa0f5e52baf88cf5a",
        "kinbench-v1/wang2020-7dof/uniform.csv": "9bfee4da9c7a9a8fc1d47772731e3a70140edab2bdfcc9a2626a9e23a036f48d",
        "kinbench-v1/wu2015-3ppr/boundary.csv": "5824daf01cd92635bfd84afe03af9701b3ba8e42d8987ba6982261c06fe824e2",
        "kinbench-v1/wu2015-3ppr/near-singular.csv": "5b43e096291fc0161ab74ffd222542458d0110be0bb354f2344c8ffefae4dd8e",
        "kinbench-v1/wu2015-3ppr/printed.csv": "7e9103b825c3d90e08949e0c7fc4011bea1e533b674055cbc4f1a519b49f0bd6",
        "kinbench-v1/wu2015-3ppr/uniform.csv": "a5414a34fa5b5d6b8fdc1c81114a5e4a5af2544bed16560a676ad310334531da",
    }),
    "kinbench-v2": Release(fitness=1, files={
        "kinbench-v2/chang2024-3rpupc/boundary.csv": "fd00a3689e140b1c59190a764c4f584353e4107f1bc75fc480f0ed9fae10701f",
        "kinbench-v2/chang2024-3rpupc/near-singular.csv": "6b51c9750eb129f423bdf0b544694bdc25c80976afc23d41632d041da4ec6551",
        "kinbench-v2/chang2024-3rpupc/printed.csv": "451c7302a371ec63c2d48f653a8c58c7968898120313b32982b3a202202d6b9b",
        "kinbench-v2/chang2024-3rpupc/uniform.csv": "e981713a2ac9591ea18eed177351dccd7f7f50d5c234d81f1e1da879a409fe63",
        "kinbench-v2/dietmaier-6sps/boundary.csv": "a877a1dec1a797b1d2abeac336836bc6b09445e85c8da3e39e9547c70fa6bb7f",
        "kinbench-v2/dietmaier-6sps/near-singular.csv": "9c5e553a27eb4f1bf370f8fbb85e72664d2af25bb7c1a18bb18be6de29bea758",
        "kinbench-v2/dietmaier-6sps/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v2/dietmaier-6sps/uniform.csv": "ff51c7798457b99c9e3e21b1c2f477db0754d85c53b51401da30481fe9349a49",
        "kinbench-v2/kinova-j2s6s200/boundary.csv": "22589bd8700cb162f1837dd5f0b988c7a01c3085bafdeaf2bfc33f293a986c4a",
        "kinbench-v2/kinova-j2s6s200/near-singular.csv": "47afdc3f73213d680c5749e1bdca8bae10d4ac843cdd5928bbfe2bd879dff3e0",
        "kinbench-v2/kinova-j2s6s200/printed.csv": "54ec9ae6569c0f1049b7986fe63ccc6b7dfced0764dfd3f63ad52ff0b47cfbc3",
        "kinbench-v2/kinova-j2s6s200/uniform.csv": "e1a225c37a5dc9ec0d0bba7d5b000fe42d60bc0f1352fcd9baaffe6b713ba70f",
        "kinbench-v2/liu2008-6sps/boundary.csv": "717d56b7395f21417bffc9ea6de61bb100822e56c11880706ac5bb580020c176",
        "kinbench-v2/liu2008-6sps/near-singular.csv": "680ab9a00e5bd3972b38e0f6aa35d3bb61f50990c35697dd5f27b9f3b1706371",
        "kinbench-v2/liu2008-6sps/printed.csv": "b6269d8a976c729a1666ac31dcbdadf01096f5cbb5ca27666742c237200b91a0",
        "kinbench-v2/liu2008-6sps/uniform.csv": "22e33b443cc8205613d19bd7d2fad9b95ef4ba68aac077198b820be985198194",
        "kinbench-v2/manifest.json": "8d76a07dc180f14a67aa209a599ec09777d00c86521602d534ef387bcf4ac3d2",
        "kinbench-v2/mao2017-3rps/boundary.csv": "2d4b32250e135ae24732759fd14db8b51b5f7f2bfce435ef3d821795582c79ac",
        "kinbench-v2/mao2017-3rps/near-singular.csv": "54fef577662f8f7ab058359201d74583c1f67592ab1c31593c0f6c81749307b5",
        "kinbench-v2/mao2017-3rps/printed.csv": "0939d3cc3902fbb5e434486b25aa6b87514614541c5ef08e858fbdc2690de675",
        "kinbench-v2/mao2017-3rps/uniform.csv": "a6e288f2317a1fc24110cb542796a37725abd6dbb447128b321ba5310027acef",
        "kinbench-v2/panda/boundary.csv": "b3f4def774bb131a9a3d25d1bd30dd57ca9c460e73393c3d21c093d527160b27",
        "kinbench-v2/panda/near-singular.csv": "86718496379a878db3c0989f9d4e5b5ee88c10ce220cd1cafc150b863b5426ce",
        "kinbench-v2/panda/printed.csv": "fb3f1fb8dd3b280c24ccfbaa4026fc2aa3212809f858b186e72e573c5037dc9f",
        "kinbench-v2/panda/uniform.csv": "503287e99782bd10f2e430111a1425132b641aecbef254dd95c1cd6270525733",
        "kinbench-v2/ur5/boundary.csv": "17d59d39238e3e293401cda28cd119df7cd30b899321c54425725897f33f06e5",
        "kinbench-v2/ur5/near-singular.csv": "ec1eb74ad4ee6ae79c2f798f2afe028e8d89c9cf24ea18c0b588ebc569870a9c",
        "kinbench-v2/ur5/printed.csv": "cba884d5ba33d047e9b112ac7b78a9af2ed79033a00644028dc51d5522586671",
        "kinbench-v2/ur5/uniform.csv": "b8038f70e69f7bda482b88d5dd250df5d82bba86726147df542f8d32978cd6ac",
        "kinbench-v2/wang2020-7dof/boundary.csv": "2b165cd1267849a7e83faa0adf731e111e62d379acae7996ea5a3ca6ef70df2a",
        "kinbench-v2/wang2020-7dof/near-singular.csv": "74d297ec9d36f4fdeb6f04cddf866653108fcf87872c204ce69c3ef4bb486923",
        "kinbench-v2/wang2020-7dof/printed.csv": "a3debf7e8247f002fbc8aa6f22a6264f36e3ed68b1c6a7caa0f5e52baf88cf5a",
        "kinbench-v2/wang2020-7dof/uniform.csv": "9bfee4da9c7a9a8fc1d47772731e3a70140edab2bdfcc9a2626a9e23a036f48d",
        "kinbench-v2/wu2015-3ppr/boundary.csv": "5824daf01cd92635bfd84afe03af9701b3ba8e42d8987ba6982261c06fe824e2",
        "kinbench-v2/wu2015-3ppr/near-singular.csv": "5b43e096291fc0161ab74ffd222542458d0110be0bb354f2344c8ffefae4dd8e",
        "kinbench-v2/wu2015-3ppr/printed.csv": "7e9103b825c3d90e08949e0c7fc4011bea1e533b674055cbc4f1a519b49f0bd6",
        "kinbench-v2/wu2015-3ppr/uniform.csv": "a5414a34fa5b5d6b8fdc1c81114a5e4a5af2544bed16560a676ad310334531da",
        "robots/kinova-j2s6s200.urdf": "984f244dc42fdf7426f689c45b8d9f19da97cf1d054b9e0503dddb56c033ea9f",
        "robots/panda.urdf": "798c686857026fd29ec7d096eb90299dc149407b63b8cbfac37cf447f12a4f73",
        "robots/ur5.urdf": "0550334fd0085f11e71945520d0180a7c224e1002e7723ff8e26ae30bcc9852c",
    }),
}




def _base(config, files) -> Path:
    """Where the suite's relative files are: ``files``, else the suite file's folder."""
    from fkopt.run.config_base import files_folder
    base = files if files is not None else files_folder(config)
    return Path(base if base is not None else ".")


def problem_files(config) -> list[str]:
    """The files the suite's problems read (mechanism file fields), relative to the suite's folder."""
    from fkopt import registry
    out = []
    for problem in config.problems:
        cls = registry.mechanism_class(problem.mechanism.name)
        for key in getattr(cls, "file_fields", ()):
            value = problem.mechanism.geometry.get(key)
            if isinstance(value, str) and value and not Path(value).is_absolute():
                out.append(Path(value).as_posix())
    return sorted(set(out))


def release_files(config, files: Path | None = None) -> dict[str, str]:
    """path -> SHA-256 of every file of ``config``'s version: the pose-set folder and the problem files."""
    base = _base(config, files)
    folder = base / config.pose_sets
    names = sorted(p.relative_to(base).as_posix() for p in folder.rglob("*") if p.is_file())
    return {name: stored_sha256(base / name, MAX_INPUT_BYTES) for name in names + problem_files(config)}


def released_name(config, manifest: dict) -> str | None:
    """The released version ``config`` claims to be (by its folder or its manifest), or None."""
    for name in (config.pose_sets, manifest.get("version")):
        if name in RELEASES:
            return name
    return None


def check_release(config, manifest: dict, files: Path | None = None) -> None:
    """Refuse (one line) a suite naming a released version whose files or fitness differ from it
    (``files``: where the suite's relative files are, default the suite file's folder)."""
    name = released_name(config, manifest)
    if name is None:
        return
    release = RELEASES[name]
    new = "; a changed suite must name itself a new version (a new pose_sets folder and manifest version)"
    if release.fitness != FITNESS_VERSION:
        raise FkoptError(f"pose_sets: {name} was released with fitness definitions version {release.fitness}, "
                         f"this fkopt has version {FITNESS_VERSION} (CHANGES.md){new}")
    base = _base(config, files)
    folder = base / config.pose_sets
    # the release's pose sets are in the folder named as the version; a copy may be named otherwise
    expected = {(f"{config.pose_sets}/{k.split('/', 1)[1]}" if k.startswith(name + "/") else k): v
                for k, v in release.files.items()}
    for rel, digest in sorted(expected.items(), key=lambda kv: kv[0].endswith("/manifest.json")):  # data first
        path = base / rel
        if not path.is_file():
            raise FkoptError(f"{path}: missing; it is part of released {name}{new}")
        found = stored_sha256(path, MAX_INPUT_BYTES)
        if found != digest:
            raise FkoptError(f"{path}: differs from released {name} (SHA-256 {found[:16]}..., "
                             f"released {digest[:16]}...){new}")
    for path in sorted(folder.rglob("*")):
        if path.is_file() and path.relative_to(base).as_posix() not in expected:
            raise FkoptError(f"{path}: not part of released {name}{new}")
    for rel in problem_files(config):
        if rel not in expected:
            raise FkoptError(f"{base / rel}: problem file not part of released {name}{new}")


#: Frozen per-robot board versions (a suite's clock track): what the entries are and how they run.
#: A changed entry (a new wrapper, another tolerance, another restart loop) is a new board version,
#: never an edit of one; meta.json names the version a stored board was made with, CITATION.cff
#: lists them so a paper can cite the board it compared against.
BOARDS: dict[str, dict[str, str]] = {
    "kinbench-v3-robots": {
        "1": "the first per-robot board: TRAC-IK, pinocchio's CLIK and ikpy through kinbench's first wrappers "
             "(TRAC-IK's two threads unpinned, eps 1e-5 per twist component, scipy quaternion in the call; CLIK "
             "undamped full steps; ikpy symbolic=False)",
        "2": "every outside entry as its authors run it (docs/kinbench.md, 'Outside entries'): TRAC-IK eps 1e-5/sqrt(3) "
             "pinned to one core, pin-clik/ikpy/pink/black boxes in one restart loop "
             "(fkopt/adapters/field/restarts.py), ikpy at its defaults; new entries eaik, optik, pink; CPU time per "
             "call and the load average stored",
    },
}


def board_version(suite: str) -> str | None:
    """The current board version of suite ``suite`` ("kinbench-v3-robots/2"; its quick tier,
    ``<name>-quick``, has its suite's), None when it has none."""
    name = suite.removesuffix("-quick")
    versions = BOARDS.get(name)
    return f"{name}/{max(versions, key=int)}" if versions else None

