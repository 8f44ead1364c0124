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
from fkopt import registry
from fkopt.run.config_base import files_folder


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
    # v3: its pose sets and the 24 robot files of kinbench-v3.yaml (kinbench-v3-robots.yaml names 23 of
    # them); python -m fkopt.kinbench.freeze release configs/suites/kinbench-v3.yaml
    "kinbench-v3": Release(fitness=1, files={
        "kinbench-v3/baxter-left/boundary.csv": "65718055eb272ff7efb7590a429dd80f672c4768eb49da1e3a963077c1911a99",
        "kinbench-v3/baxter-left/near-singular.csv": "2ea9ed84566668ddbef2143c7427a5733ae4576a5c727efd2748399ed50f56bd",
        "kinbench-v3/baxter-left/printed.csv": "fbb330a94eda13c4ad3550bf19e957f5fff5cea433c03baf054c01dee47661aa",
        "kinbench-v3/baxter-left/uniform.csv": "2ae4765235ca089f2aca45e4da2af791458ebba7a64bde23cae02c542c4fbd51",
        "kinbench-v3/baxter-right-mj/boundary.csv": "f55d32f954856508680e4e61efe86d1ef79e131650976846d6438e8654d8f473",
        "kinbench-v3/baxter-right-mj/near-singular.csv": "b8685756ef52e6647255600c1d8ce3dc3ffb070f0b5885010f082679970605bd",
        "kinbench-v3/baxter-right-mj/printed.csv": "d4a1a77a3067fa9d94d25ed6f302526f39390d3a4d84863dc47d56b75f2b7428",
        "kinbench-v3/baxter-right-mj/uniform.csv": "0e6856ff7e033f3fc0dbceb33012121e918dd1648c05c941e5862cd6ee445501",
        "kinbench-v3/chang2024-3rpupc-i1/boundary.csv": "1c514972f52a68606d08e7fd07bc0da6db039080aff73e532b58c820edb569da",
        "kinbench-v3/chang2024-3rpupc-i1/near-singular.csv": "715cfb320b3fe307d307e383ecddec036b948db3919b3dccb8f7960d68cafaf8",
        "kinbench-v3/chang2024-3rpupc-i1/printed.csv": "320930967132ee3eca46f6f0aa1bfd525051b0bb89ce597e3b08154fa9f2932a",
        "kinbench-v3/chang2024-3rpupc-i1/uniform.csv": "bb0d460f655c51780faa4004c31dfe813697c2fc74bf3e40039a4d82e542e7da",
        "kinbench-v3/chang2024-3rpupc-i10/boundary.csv": "8ba903f70c452be34b31b7cc02e392bb453cd98c9d971aec8eda4fbea3aa75f7",
        "kinbench-v3/chang2024-3rpupc-i10/near-singular.csv": "97a1ab7a12d1130d2e51b2318494b4d95a36540221b8f7902b67f5e3bb53850e",
        "kinbench-v3/chang2024-3rpupc-i10/printed.csv": "320930967132ee3eca46f6f0aa1bfd525051b0bb89ce597e3b08154fa9f2932a",
        "kinbench-v3/chang2024-3rpupc-i10/uniform.csv": "06f64020255e4101b04f147b8ee202b0c422816aa3a510d1d484116c3bd1678c",
        "kinbench-v3/chang2024-3rpupc-i2/boundary.csv": "2f95c0e3005020381dc4e1eb0f3f40a051f80b6f17b8b061c91af6a226736b18",
        "kinbench-v3/chang2024-3rpupc-i2/near-singular.csv": "637e269799a2bd337dc58394a15dfaf3bfd1f9a5a1b30625fa38d4c39c071ece",
        "kinbench-v3/chang2024-3rpupc-i2/printed.csv": "320930967132ee3eca46f6f0aa1bfd525051b0bb89ce597e3b08154fa9f2932a",
        "kinbench-v3/chang2024-3rpupc-i2/uniform.csv": "e7579775eac613dd152ceb97fa0bd9f1ce183cc7e37d4e04fe128df45b9c6208",
        "kinbench-v3/chang2024-3rpupc-i3/boundary.csv": "e4def815a3a23747995950e1ee70877130ff58ea4951cd34e777f0d9d0aef9ee",
        "kinbench-v3/chang2024-3rpupc-i3/near-singular.csv": "453b8574d6f7b2862de6fcde024c7e04fe89932c95880d26d3660bee9bb46c7f",
        "kinbench-v3/chang2024-3rpupc-i3/printed.csv": "320930967132ee3eca46f6f0aa1bfd525051b0bb89ce597e3b08154fa9f2932a",
        "kinbench-v3/chang2024-3rpupc-i3/uniform.csv": "ae460a8fee3f2a23cc56138373083221c76bf030ffa2ee9eb7348c1c783651c0",
        "kinbench-v3/chang2024-3rpupc-i4/boundary.csv": "2503431cc72e127e8d90395a001b505812fa1d2512677cc5f34bdeef6f860396",
        "kinbench-v3/chang2024-3rpupc-i4/near-singular.csv": "baf70e5bb3deb740d861a41f736b66504171de7e8bd697e24b60330080b65c73",
        "kinbench-v3/chang2024-3rpupc-i4/printed.csv": "320930967132ee3eca46f6f0aa1bfd525051b0bb89ce597e3b08154fa9f2932a",
        "kinbench-v3/chang2024-3rpupc-i4/uniform.csv": "e158a70aaa8c88060e8a6b2cc7298d3b7136a91c9c5a1332b076d3b1a5bf934b",
        "kinbench-v3/chang2024-3rpupc-i5/boundary.csv": "1457b0155ba95128d82e7cc4131154abf9af09f5b07bc62707d4da5558ff5ed1",
        "kinbench-v3/chang2024-3rpupc-i5/near-singular.csv": "199ad9c586ec6db56d6f7f0ad3b9cf5f01a3a6a09b4905abc241fda2f83ef27c",
        "kinbench-v3/chang2024-3rpupc-i5/printed.csv": "320930967132ee3eca46f6f0aa1bfd525051b0bb89ce597e3b08154fa9f2932a",
        "kinbench-v3/chang2024-3rpupc-i5/uniform.csv": "97bd90360241733a6258e5f9b9f53acf686b7be7692ed45d9e3726a125ee9634",
        "kinbench-v3/chang2024-3rpupc-i6/boundary.csv": "4550fd31a1fb407721f108b6634d9e8540ced47b936823a04ef87086e09339ba",
        "kinbench-v3/chang2024-3rpupc-i6/near-singular.csv": "eeb38d7ee6ffb5a21c79de6b331e86de19d5594f6e7657e63c9fb7c6674b0bc6",
        "kinbench-v3/chang2024-3rpupc-i6/printed.csv": "320930967132ee3eca46f6f0aa1bfd525051b0bb89ce597e3b08154fa9f2932a",
        "kinbench-v3/chang2024-3rpupc-i6/uniform.csv": "d816cd69f9027575a16c4347ac1cdfa96189dfcc45c094be3a32561a9efa6fc1",
        "kinbench-v3/chang2024-3rpupc-i7/boundary.csv": "caedf15521d3d6d38c1d8cbd3702c5ecc1332e9777a0749f056d8b5b136a4984",
        "kinbench-v3/chang2024-3rpupc-i7/near-singular.csv": "9966ee5a684fe670ce5e870406e3af4700bd9957f40329ad3906a98221e5c555",
        "kinbench-v3/chang2024-3rpupc-i7/printed.csv": "320930967132ee3eca46f6f0aa1bfd525051b0bb89ce597e3b08154fa9f2932a",
        "kinbench-v3/chang2024-3rpupc-i7/uniform.csv": "c07a1b5b607085c1ccc2d5fce54e2a69cc19730f8be9a589a770a231d34070cb",
        "kinbench-v3/chang2024-3rpupc-i8/boundary.csv": "65f64e3a7e83829f4714b6c4ee90e4d3c38c0a0c7883966ff6a4d7f3b421e93c",
        "kinbench-v3/chang2024-3rpupc-i8/near-singular.csv": "40dc992726e3cd219528f36fe5a36682f88ecf8c3a58ce60c72ddafdcb4a29bf",
        "kinbench-v3/chang2024-3rpupc-i8/printed.csv": "320930967132ee3eca46f6f0aa1bfd525051b0bb89ce597e3b08154fa9f2932a",
        "kinbench-v3/chang2024-3rpupc-i8/uniform.csv": "8a73bef9df4761d1155c383d6b0231924f653936973518cc33009bbeb2005a48",
        "kinbench-v3/chang2024-3rpupc-i9/boundary.csv": "a1c5520907274bdfcac386cdf681c9efd986ae4b21bc8cede44a9715adb6d8ce",
        "kinbench-v3/chang2024-3rpupc-i9/near-singular.csv": "1b37c25a2a415815e2ac58ad694e4bad39f8080c3b6e0616ba0c5dbaa9feccaa",
        "kinbench-v3/chang2024-3rpupc-i9/printed.csv": "320930967132ee3eca46f6f0aa1bfd525051b0bb89ce597e3b08154fa9f2932a",
        "kinbench-v3/chang2024-3rpupc-i9/uniform.csv": "01b80c78e9d36f149b1801e982160f1e502c242b7bb40e63aac84f9e8f5878a7",
        "kinbench-v3/chang2024-3rpupc/boundary.csv": "52c09da81810eb9874c7bf40d34b4042bad30eb605731357fbb0fc5f90805ce6",
        "kinbench-v3/chang2024-3rpupc/near-singular.csv": "ba35ef04f19b8133d53ac3498aae01d5c716ef484bd8f4073fadda2f2587b28d",
        "kinbench-v3/chang2024-3rpupc/printed.csv": "451c7302a371ec63c2d48f653a8c58c7968898120313b32982b3a202202d6b9b",
        "kinbench-v3/chang2024-3rpupc/uniform.csv": "c45a2054e01f1f4643cbbf8b93b38a230409a35bdd25620451ba8e6e1a2db608",
        "kinbench-v3/dh-chain-10/boundary.csv": "cdcd828420ac6beb9666eaf7a3c0b82a136a4302860cea90efa7850d3cb4a60b",
        "kinbench-v3/dh-chain-10/near-singular.csv": "0975c15fdfe519eb5fa36cb32553790e75b9a434ce065bf9b45f086b89f4cefe",
        "kinbench-v3/dh-chain-10/printed.csv": "1060eab4d385ac8cbc359e37e60da9a7ebb2230ecadf63f25648b135d54eb0ed",
        "kinbench-v3/dh-chain-10/uniform.csv": "fa797a491992159f6d57e12deda1741557ab9906f39a377ac2f340362d769384",
        "kinbench-v3/dh-chain-12/boundary.csv": "a747606b183010af6efe553e3fd378937a897c02cb9da76ae8b19e4b5663ff0d",
        "kinbench-v3/dh-chain-12/near-singular.csv": "8820b7130df17a58d71500991a4bd08b08b4b29f9f46ac28d49c872732a05462",
        "kinbench-v3/dh-chain-12/printed.csv": "87909ce30471488220fba4dde4e866bc7d1189e7e2b1471a81cf0a4782639351",
        "kinbench-v3/dh-chain-12/uniform.csv": "fefbadb9f0f628fd3398426da49f25eb1079af31612a099b82ff867f114d9318",
        "kinbench-v3/dh-chain-15/boundary.csv": "879a1bb06e730c90d28e55f653de13509c8b690845c6b5b616b4b885ea8c7dfb",
        "kinbench-v3/dh-chain-15/near-singular.csv": "60f99a2acb062db93312a8e067003aa9c52e305cb0dbe82abf26f338b04d2e23",
        "kinbench-v3/dh-chain-15/printed.csv": "ef5272fbe9312f3039930a04f779d3206aac33cccf20400e5e0a554810d820d5",
        "kinbench-v3/dh-chain-15/uniform.csv": "9dc790aeaecfc442d903f155c451623eb4713b9f3b9c7a7119110071fb038fcd",
        "kinbench-v3/dh-chain-20/boundary.csv": "8a6b16915cdd3a602ab2d548b769d161419586382e9e5a419110caab6b6d7f86",
        "kinbench-v3/dh-chain-20/near-singular.csv": "43b60a06dac847859eb84c70b6dc5645ecd0b0f3e7341e2fd280f7d78146b4d9",
        "kinbench-v3/dh-chain-20/printed.csv": "57ff6cf37c5af8341929e0d6bf15bbac6e0218e262904c84f6dd4842af621efb",
        "kinbench-v3/dh-chain-20/uniform.csv": "fb00c705a8f2a1745793e251f6372686e1f3861f859c6bf2b43c3e8db1f41f84",
        "kinbench-v3/dh-chain-25/boundary.csv": "1eb8cb5132c6ab2081f7365d1a70d51acb96c40942368e556ff839fe53694763",
        "kinbench-v3/dh-chain-25/near-singular.csv": "8ec27337f4b3096dcac1e1e531fce66571b57c0fdb07ad690f160d99faeebb49",
        "kinbench-v3/dh-chain-25/printed.csv": "40bfa86a0d6566f17f5f59879aa975ec19203c6ce153a7f35bce94d4ed8d175a",
        "kinbench-v3/dh-chain-25/uniform.csv": "dd8ec5d41fcdaece8efb1e9e543c1ccdc91de551d412eb4b6f1d14789136e522",
        "kinbench-v3/dh-chain-3/boundary.csv": "00c03a4fc6f8b0521d8c82dace704ab11ef2f27755037c66d2ac3fb9c4cef84a",
        "kinbench-v3/dh-chain-3/near-singular.csv": "15e7c1be896ad627bf41da45dc8d101141f3e4f1228fa54f80c4d0231b98bffd",
        "kinbench-v3/dh-chain-3/printed.csv": "4530e8e323239ec0b9c95e10f696bf608f2af13f9949b2e0c1673a1acb733cf1",
        "kinbench-v3/dh-chain-3/uniform.csv": "1df388c707a557aedd81916c081562d8a8e3667eb8488eb2ebdcf20f330609ab",
        "kinbench-v3/dh-chain-30/boundary.csv": "d31aebafe47d713f349629b1fa010da7035921713826bd87ecbcef3dcf03dac4",
        "kinbench-v3/dh-chain-30/near-singular.csv": "03eae699ebf26f5465e839b9e8130d8e41ed5e8b5fc1780d630c446202661888",
        "kinbench-v3/dh-chain-30/printed.csv": "4dee4c9c13b5905d9b0e945632b84c8a83916581eeb83698e699cd0a530752b8",
        "kinbench-v3/dh-chain-30/uniform.csv": "3fec851e891238d9b92bb58df39f11ae039311796b9967f1b9c89bcdd763c0ea",
        "kinbench-v3/dh-chain-4/boundary.csv": "7d48fac39a1aea0ba7806a200f92e3b3a4b94c42d8c8e4516120c426eddac49c",
        "kinbench-v3/dh-chain-4/near-singular.csv": "4389b5510250f5a3d1bef20c7176d044d65ce7d8aeb26e524617e6e273882352",
        "kinbench-v3/dh-chain-4/printed.csv": "275d67dfd9811b30467d2989f78a4c60526dcccf8d51dc20e33ba29a6b3ea27a",
        "kinbench-v3/dh-chain-4/uniform.csv": "e9073dc7ac9b836e5a23c197eb4c5f38b6f9d65bd791ff99b4224ccf83919b17",
        "kinbench-v3/dh-chain-5/boundary.csv": "ac70ed6af5591d5a0ee3599fe3fe9f5320c33eb4f74a4eef84bafbd97e2226a5",
        "kinbench-v3/dh-chain-5/near-singular.csv": "3e91d7a2c8a02c922b5ad6aeff43df887206ee270d7ebc32fb17ea2e04b823ee",
        "kinbench-v3/dh-chain-5/printed.csv": "24646132dc0d5b51b281bdf079510c51d63d4cadd4d60189cc62df4d7639cc13",
        "kinbench-v3/dh-chain-5/uniform.csv": "9e763f825b3e41033290e2aa03b7fcc31ed973fde683e93400537d3863ea34b7",
        "kinbench-v3/dh-chain-6/boundary.csv": "f5bfa1638f501b1cebef1847c75b624bc108d9fa9e4a3f491b363d6b9737a173",
        "kinbench-v3/dh-chain-6/near-singular.csv": "180cdfc64915cfc39db6d6e51a2f12299da7de95c682768d9078ad228bac29b8",
        "kinbench-v3/dh-chain-6/printed.csv": "f0ea65e98e2d1c6034839c373707f0377cf3adc10af2a2f20af128fe62c23ff1",
        "kinbench-v3/dh-chain-6/uniform.csv": "0b15dfc117bee59a840a16b7101e98deaaf3502aff385bba61e717d39c42502a",
        "kinbench-v3/dh-chain-7/boundary.csv": "59ac5263891ace370079b6d25c6966da7100249b08df583fb8a99578c8791e64",
        "kinbench-v3/dh-chain-7/near-singular.csv": "e877d182381dc8da9efd7dd5f8041114db7ccd9695ac24cb3b747aa7067a076e",
        "kinbench-v3/dh-chain-7/printed.csv": "e4550bf52095c169b9bdea244894c697efdcb17faf3a448c3705fce610fba316",
        "kinbench-v3/dh-chain-7/uniform.csv": "7125f69db0132f2bbe0ca3c225ed05d3d2e61f1c0ee35ed9e74fa0b4a3830c1e",
        "kinbench-v3/dh-chain-8/boundary.csv": "7a992802d743c668e1cef503411e91f0f9b37f4c5667286588b33ac940e1ae51",
        "kinbench-v3/dh-chain-8/near-singular.csv": "e1fc99c95a3f1f466ecd776100dc683f0926806ec199c55403085df76055bb31",
        "kinbench-v3/dh-chain-8/printed.csv": "b863ad55f12808f27a5e69ca23e34dafedd2501f1b0f101203b936c644904fc7",
        "kinbench-v3/dh-chain-8/uniform.csv": "f6b446811cc5ff7b93ffaae645ef222f8e95f806450aa89612a936c8d8031e72",
        "kinbench-v3/dietmaier-6sps-i1/boundary.csv": "10456ee561106411bca0a6e154456a504e25f0861b99e7b98a3c1d9b79d1d4e5",
        "kinbench-v3/dietmaier-6sps-i1/near-singular.csv": "2fcb6a7f3a9101d057876425903c339d04bfb12ce5ae990b5b726b8e7aa3a4ed",
        "kinbench-v3/dietmaier-6sps-i1/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/dietmaier-6sps-i1/uniform.csv": "e89b38d6e50f4e88862946490b7e47b1db38b0aaeaf6c003f356a0dadc37203d",
        "kinbench-v3/dietmaier-6sps-i10/boundary.csv": "79100b801445cf350c19a64d98c744f44ba22b379e8431d81f18745af8e10624",
        "kinbench-v3/dietmaier-6sps-i10/near-singular.csv": "7decc1412d4ed1c3ea7e391791f38bf5dbe15d8a9d5e36046fea3927e9033111",
        "kinbench-v3/dietmaier-6sps-i10/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/dietmaier-6sps-i10/uniform.csv": "239eb3b2e72d5fc44d081e8cb3cec93954b0ef3ae1f01993efc8559560e38002",
        "kinbench-v3/dietmaier-6sps-i2/boundary.csv": "7810f3c4807df715259ae7f9d586934571cc545b9af1b8ca69bbe7347aba29d4",
        "kinbench-v3/dietmaier-6sps-i2/near-singular.csv": "8cfbf52084064e8825141a81e271f6b564732ca8a24c740b7bed5632220ca6f9",
        "kinbench-v3/dietmaier-6sps-i2/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/dietmaier-6sps-i2/uniform.csv": "04fce48038d76c62a861b0c4634d3ba9bc40c95aca9e0a1e6f611fc4026b45b1",
        "kinbench-v3/dietmaier-6sps-i3/boundary.csv": "f19e037004e2f9536024f16194b2a954326251277ec2ccf2595eac5f541b30a8",
        "kinbench-v3/dietmaier-6sps-i3/near-singular.csv": "ba42612fecde4abfca65dd9b2171e1e6e2f5e0c54b9566f1155d4db76fc782a9",
        "kinbench-v3/dietmaier-6sps-i3/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/dietmaier-6sps-i3/uniform.csv": "eb13f80146f63843ae4eb8660dd462e4b00202a5b3fdc3064dc3836aeac7acc3",
        "kinbench-v3/dietmaier-6sps-i4/boundary.csv": "2d32ab680444755492a312d4ee866e63dffb08d1acfbbd9bafb90f08efe3fdd6",
        "kinbench-v3/dietmaier-6sps-i4/near-singular.csv": "8593c171f0551c98b19e8579fd8088bd986e8e34c3a493a854da248a93bf6fcf",
        "kinbench-v3/dietmaier-6sps-i4/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/dietmaier-6sps-i4/uniform.csv": "e72a054df33e93d365727c20b34aaada4fda4e346a32347ad34eaa7f59678476",
        "kinbench-v3/dietmaier-6sps-i5/boundary.csv": "d1827e79cbc643e309e7722f9675548e5245c092580defcfe9c3349884bd51b0",
        "kinbench-v3/dietmaier-6sps-i5/near-singular.csv": "2d97cc0a237801aa68e825d75afc6f42ee17a12ae5e4124709f7b566da928ee9",
        "kinbench-v3/dietmaier-6sps-i5/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/dietmaier-6sps-i5/uniform.csv": "cb7cc5fdd17a2b41e387a9a7577fca26a2eda97a0f1ea705873fb317a3edde04",
        "kinbench-v3/dietmaier-6sps-i6/boundary.csv": "6e52069795820377c32f6d2c7b07c0ebadd00b435b25aaa2b6fd8c741b3f9035",
        "kinbench-v3/dietmaier-6sps-i6/near-singular.csv": "0df2c9e63f0d884bacd510771fdd22967b266e27f4bccf015594986b8a8e5e1f",
        "kinbench-v3/dietmaier-6sps-i6/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/dietmaier-6sps-i6/uniform.csv": "04a2cad2da17218a927b6c38f677ba14a0625bdf369312ad32a7f2aa29fb1239",
        "kinbench-v3/dietmaier-6sps-i7/boundary.csv": "00557db367a6a9e66dbc35301580c5db7c3a3ef3f9b3439ac6a3d80e4de51402",
        "kinbench-v3/dietmaier-6sps-i7/near-singular.csv": "afbc4906ee164b4165b96d781ec589baa11e0343d7acbc79bcf0fe20a6506a26",
        "kinbench-v3/dietmaier-6sps-i7/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/dietmaier-6sps-i7/uniform.csv": "44f0863ddbf57da1f2716ebdb8eb4c971888752f34c9d5a75667cd6a439787b9",
        "kinbench-v3/dietmaier-6sps-i8/boundary.csv": "a4102dda4784578e5eeee2148eb5e408ced9fa549dfebd69099c4df196d26b3e",
        "kinbench-v3/dietmaier-6sps-i8/near-singular.csv": "ef37fb01e24594a50904ecbf6596b8ba81aa38162f5d8f840b7a59f698cbbeff",
        "kinbench-v3/dietmaier-6sps-i8/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/dietmaier-6sps-i8/uniform.csv": "71bbce6bcafcfcf8bca05a6865580a1d04873982e2b576f3eb4bdcba94839b3f",
        "kinbench-v3/dietmaier-6sps-i9/boundary.csv": "e9327ec94b8344060252c7acc319bd9602f8222046b7c3f8923c3e280649f401",
        "kinbench-v3/dietmaier-6sps-i9/near-singular.csv": "92a76bd75c2ce997bce8ae9bbd90db1add8ff82323985d49ce25e4b65e30b0a7",
        "kinbench-v3/dietmaier-6sps-i9/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/dietmaier-6sps-i9/uniform.csv": "b89261468d9efaccb9f958edaf764c8cd4695099db8fed24a2d7d8083cf5a2a9",
        "kinbench-v3/dietmaier-6sps/boundary.csv": "4348f62101aa8e90708e3265559a9bc3627facd207c11256daad125c156145ea",
        "kinbench-v3/dietmaier-6sps/near-singular.csv": "9da9c049fbffd7c52a2b1b57948743232ce1fe3cf20617d707af934509ac05c6",
        "kinbench-v3/dietmaier-6sps/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/dietmaier-6sps/uniform.csv": "9a54a71ac6cf83a9c650aa70c3ff318840f25a96b5ba9aa0d06c11e75073752c",
        "kinbench-v3/g1-left/boundary.csv": "adb6a4ef18aa65400d1066f07464bf954dcd5aeed67abf4b03368f4b50cc88f4",
        "kinbench-v3/g1-left/near-singular.csv": "8ecfcb591e2b4402d9f03f850c4c9f521cd625c64be9667d2d17a77c7cdfcf86",
        "kinbench-v3/g1-left/printed.csv": "64768d3145e910f6749e9a72688639a5969444187836cf48cb3e1fc3762e2bbb",
        "kinbench-v3/g1-left/uniform.csv": "ee2320f28fb7c826dfcbf7ff123b89be15386743e8e0aa6a8ebb176fd2dcbe93",
        "kinbench-v3/gr1-left-mj/boundary.csv": "5b777809f609fe46daafdf7fe16b88631f5bcd1f5d1d53825d2d6ffcfe53d2c6",
        "kinbench-v3/gr1-left-mj/near-singular.csv": "8203a737101b61478dde1ca3d82a357c3adbbc648defdce84efd35d22e800136",
        "kinbench-v3/gr1-left-mj/printed.csv": "0499d530f4926e6e1db7a539e6ab882667eac8bdd3986a819e43cf3f74bb9eff",
        "kinbench-v3/gr1-left-mj/uniform.csv": "c7c1350dbcb3dadf4c621d087aaff0e6ddb862534516e7ae015bdb8f2d028bc2",
        "kinbench-v3/icub-left/boundary.csv": "09292160b2021aca85d6f806f5b26411ee34201675611b472fd4d8036072e7b6",
        "kinbench-v3/icub-left/near-singular.csv": "2666c9d41c16e67a5a5ccbba3dc3b0a9ec0d72b23fda628bd83d77344061a11f",
        "kinbench-v3/icub-left/printed.csv": "da873331324eb8e3dad6364606e45e41be7a60c658f29f82707fbef00c439518",
        "kinbench-v3/icub-left/uniform.csv": "d19cf39ee18a446b158dd0662d4f632a2845ac1a798f81e44b1946ad287eb8f5",
        "kinbench-v3/iiwa-mj/boundary.csv": "3e15dba07c04cf35b88c07df698896b064f4bb695bd24ddda66617cb5df2e6f0",
        "kinbench-v3/iiwa-mj/near-singular.csv": "4256839e32f7ab0df297bffde3354a4c4c3f3e728395aeac0b77e9c34dbaa6a4",
        "kinbench-v3/iiwa-mj/printed.csv": "02332eb2c0560388158b9f8b85cc14f4a50110fc18a063aad734a28345673314",
        "kinbench-v3/iiwa-mj/uniform.csv": "2c2525dbe32527dfa4632e41868ade35664316e56de82b9a5696faed1643d822",
        "kinbench-v3/jaco-mj/boundary.csv": "c2d0a6e1c7f387284f522da6bf2922228144e05b8abee5035ecca8cbeec03b81",
        "kinbench-v3/jaco-mj/near-singular.csv": "2090bf56a30ffd533f27cce19b7909fe205dfce7efab6b316537642e9bdb7fdf",
        "kinbench-v3/jaco-mj/printed.csv": "44bb4ae00f2fcdd99cb6f70d917c14a6d65a948d34f42e49784856baacdff5e4",
        "kinbench-v3/jaco-mj/uniform.csv": "0bdc717a39fde3d11604b2a6a81fd85a4ab4cccf498f204ad7623248b61dc3a8",
        "kinbench-v3/kinova-j2s6s200/boundary.csv": "107b937cccccee2efb4d00c1dd9caad3fe08f4a043d40c95d96ccc0206c25443",
        "kinbench-v3/kinova-j2s6s200/near-singular.csv": "e420d1ca2d64acf047a4bbb1d46df362d10f6864ffdefc4fc847e7b3f37f8f1d",
        "kinbench-v3/kinova-j2s6s200/printed.csv": "54ec9ae6569c0f1049b7986fe63ccc6b7dfced0764dfd3f63ad52ff0b47cfbc3",
        "kinbench-v3/kinova-j2s6s200/uniform.csv": "a8273c09b360fc5811c53a7a98f9a62667f7f9de9b58319adfb59a3e1c8f804a",
        "kinbench-v3/kinova3-mj/boundary.csv": "7d75fbb3538edc7edab76fff374e4fcf34d9970feffead944dba61d9fedbb226",
        "kinbench-v3/kinova3-mj/near-singular.csv": "c57d4d445326c43d5a480c5465018b34ab6f4d3fa425f59ee80c70157b95af6e",
        "kinbench-v3/kinova3-mj/printed.csv": "cc2d0eea3893994bbc7f6d1187f5878200241e9d1c1c4cce3b835f68112ef44a",
        "kinbench-v3/kinova3-mj/uniform.csv": "ba6f5d2945d25919d2212fd6a1534daa5ce0c20a20edbc53e57a76da55cd5b75",
        "kinbench-v3/liu2008-6sps-i1/boundary.csv": "29ff560f75f52dc5f40f8435559deea6c0b0722a9aac8892e76523cd2382c47c",
        "kinbench-v3/liu2008-6sps-i1/near-singular.csv": "39886a6fb74c00edebf174f33e46c2af0481ae8faa48ab321a007d4f77986048",
        "kinbench-v3/liu2008-6sps-i1/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/liu2008-6sps-i1/uniform.csv": "f9c6da5f80f7e70c4d84ec14f9c93f92c6eac8acaa79e33d16a30441446fbf0e",
        "kinbench-v3/liu2008-6sps-i10/boundary.csv": "c61cd40128a330ae17c1081c32c037f229f54452b295c91e5e46c09f98669bfb",
        "kinbench-v3/liu2008-6sps-i10/near-singular.csv": "d1046051fb79373173ac28b96d41688a815e0cf9fc361516e1ad0fb37c432586",
        "kinbench-v3/liu2008-6sps-i10/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/liu2008-6sps-i10/uniform.csv": "b309c23faa06d0ae7fa02a4e81fe90deb6b13cd835cd65c85b60d7707a96842f",
        "kinbench-v3/liu2008-6sps-i2/boundary.csv": "48c88c4df12f87922a640655c36e1ccdcff343793c70254546d7241024e83d22",
        "kinbench-v3/liu2008-6sps-i2/near-singular.csv": "cca2b3664c418d78b5d9a0cd03a9efcedc40bcf49b86c4379f310ccf5871cf69",
        "kinbench-v3/liu2008-6sps-i2/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/liu2008-6sps-i2/uniform.csv": "9801e4c02aab9504c28f9a1492bbe3caa2942808705d036b59606132c591a185",
        "kinbench-v3/liu2008-6sps-i3/boundary.csv": "8e7188e369254c484a3c70c2a79e0673e5c13f637ad9e3d57b64743f57ec95d8",
        "kinbench-v3/liu2008-6sps-i3/near-singular.csv": "93fae4e3e42ceb05cd68a1099a3073e40295fd2a02fccbaee7f7e14684ad0f88",
        "kinbench-v3/liu2008-6sps-i3/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/liu2008-6sps-i3/uniform.csv": "38f54e6b24336a1cadcf920c0b8b6e1efd35a149552f130daf8e963e8e5b335d",
        "kinbench-v3/liu2008-6sps-i4/boundary.csv": "64d6a6072fac941f1c6830dfe5d8ea10e49df54eb8797716033c2fbf618fc3b7",
        "kinbench-v3/liu2008-6sps-i4/near-singular.csv": "bca60c426ffc8ae11949d3f6f9d28429fb81a4ce847ec7b6836952d9bc167525",
        "kinbench-v3/liu2008-6sps-i4/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/liu2008-6sps-i4/uniform.csv": "2cfbb331f9c2ecff612c09c5f27c2aaf2b6a77f6a43de09ca0291d7a0703a9c2",
        "kinbench-v3/liu2008-6sps-i5/boundary.csv": "57a0c04600a5996bcabbc59623d8db1043bfdce58fc1d6aa31f727a23869ae83",
        "kinbench-v3/liu2008-6sps-i5/near-singular.csv": "99dfbeb5734303ad9f5226f13bf17ae13b4948efebfc4ea1640fedf93df3808e",
        "kinbench-v3/liu2008-6sps-i5/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/liu2008-6sps-i5/uniform.csv": "5d8fda565345dd0c7a5c48c2cd005d1a514ebe823834c5d0464e2ae29aa5e46a",
        "kinbench-v3/liu2008-6sps-i6/boundary.csv": "7d1fd3d82b16ed38014e6c92e7dd16880f9198ca8a009ba171f46c454d2f3e52",
        "kinbench-v3/liu2008-6sps-i6/near-singular.csv": "fa01eebf954d41d19a52c8c3f3a11cd589350f27ac8177aacc8abe46bb008c2a",
        "kinbench-v3/liu2008-6sps-i6/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/liu2008-6sps-i6/uniform.csv": "cfa6336c43705a2584b0d8bab44092ba414369f8d1054bf9c88f1e42d0207fb3",
        "kinbench-v3/liu2008-6sps-i7/boundary.csv": "2e15d415ce5c6a598be840c82b4bc7131ce42ea532a61df4d6f311323d2bf368",
        "kinbench-v3/liu2008-6sps-i7/near-singular.csv": "be6ca63a097da648d10b53bad0bf96fae27409c59cb8c5a39698a6a239743abb",
        "kinbench-v3/liu2008-6sps-i7/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/liu2008-6sps-i7/uniform.csv": "b406748864ce26f2afa564388d21616386288083d92222ba63a8059759691c7d",
        "kinbench-v3/liu2008-6sps-i8/boundary.csv": "b802a6a51e1cdbd94c8faeed25472da8e4abe3cb126898887af7a45887ee8232",
        "kinbench-v3/liu2008-6sps-i8/near-singular.csv": "9d8c8a625817d59936c172e3373c9db4836af6103bc6d7cebe20c93529c81365",
        "kinbench-v3/liu2008-6sps-i8/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/liu2008-6sps-i8/uniform.csv": "d14fdb0f014ab95708f778211908cfda32e60a7173af87c94a9f3e7b363348ab",
        "kinbench-v3/liu2008-6sps-i9/boundary.csv": "568fff91f352df34eae1fe88ece18726bb5d895ddb2b3ae757ca7013fcdd9ece",
        "kinbench-v3/liu2008-6sps-i9/near-singular.csv": "2fd47f7afb5577f9a67a95026ece031ad72d134157d784450fb0e533fb24cee7",
        "kinbench-v3/liu2008-6sps-i9/printed.csv": "83a319a70a9ee6ba35fdce2a1510205d8d253cbc609b27b50f23bb0b44cde0b7",
        "kinbench-v3/liu2008-6sps-i9/uniform.csv": "fd11b0ba6cf39d1d678fec06fc20f680f2a2d4c99142334e7ff7f80ab68e3699",
        "kinbench-v3/liu2008-6sps/boundary.csv": "47fde5566ddc8152ff45d21c66acda9f08c6808d1c04cd634b345c40908b7a60",
        "kinbench-v3/liu2008-6sps/near-singular.csv": "f1ac3e9343a54664d6e9a740b9b657452a823b3eb7d08964618793d9f4db4ae1",
        "kinbench-v3/liu2008-6sps/printed.csv": "b6269d8a976c729a1666ac31dcbdadf01096f5cbb5ca27666742c237200b91a0",
        "kinbench-v3/liu2008-6sps/uniform.csv": "6e07d8ce74acd044b8249c09457cf4eca91a8b1a79e0e4b3af722b0a951c008e",
        "kinbench-v3/manifest.json": "b89674f1ee5118a35cdc5a11b30e06b98c390a90dfb25e9846bafd4d1e2b6c58",
        "kinbench-v3/mao2017-3rps-i1/boundary.csv": "2080b09a7510beb7adbf93b261be304ef2dfbd6fa38855c38248201fce77e8d5",
        "kinbench-v3/mao2017-3rps-i1/near-singular.csv": "a48dfd4fa6e05b4d2b191484f4f1cf80d1e91bbc055e493e6aeed75d429d7440",
        "kinbench-v3/mao2017-3rps-i1/printed.csv": "704dec541dcd20ab7ebb3e5bee2b19fcef3c4c3841854ae428a6612144d67249",
        "kinbench-v3/mao2017-3rps-i1/uniform.csv": "4f8a013eeb24e0fdb3647442349c358146fbe456d45985fdf49957aa7974c1a8",
        "kinbench-v3/mao2017-3rps-i10/boundary.csv": "90b193f704bdcd85a0d5304fc22c4095194ef1aaaf8d9bb898596b287679fed1",
        "kinbench-v3/mao2017-3rps-i10/near-singular.csv": "279d31018333500fcd68eabf6387219a5ba6e5e2756cb13cc8853e1bd6e2a00e",
        "kinbench-v3/mao2017-3rps-i10/printed.csv": "704dec541dcd20ab7ebb3e5bee2b19fcef3c4c3841854ae428a6612144d67249",
        "kinbench-v3/mao2017-3rps-i10/uniform.csv": "532556bbdf30c8c7f7a2088306bdf900d6aac61ebee05dee56e011284ac28fd9",
        "kinbench-v3/mao2017-3rps-i2/boundary.csv": "ec0623a8df9d2ad5471b6a527b37ea4143062869c379294f091081b437d2f905",
        "kinbench-v3/mao2017-3rps-i2/near-singular.csv": "740c5c72d39c66eb67feba98bf159aee144989d835e5c2578b5d2cfc47084046",
        "kinbench-v3/mao2017-3rps-i2/printed.csv": "704dec541dcd20ab7ebb3e5bee2b19fcef3c4c3841854ae428a6612144d67249",
        "kinbench-v3/mao2017-3rps-i2/uniform.csv": "9f6132f386e1671676338c10c30ebbb24d63d012e17664354bf9468aae7baa44",
        "kinbench-v3/mao2017-3rps-i3/boundary.csv": "0d1b03c55b89b1638e5c164c53784722b2ec9b5a72b177a242e9875fd2d11292",
        "kinbench-v3/mao2017-3rps-i3/near-singular.csv": "372214a8bdc862baf29fd1824d9a43faa2725fdf34b88caaf037533bbb65456e",
        "kinbench-v3/mao2017-3rps-i3/printed.csv": "704dec541dcd20ab7ebb3e5bee2b19fcef3c4c3841854ae428a6612144d67249",
        "kinbench-v3/mao2017-3rps-i3/uniform.csv": "b671b1b7be4a21baddb9034389b586a4188b8055771bef5303a842cf5ebf923c",
        "kinbench-v3/mao2017-3rps-i4/boundary.csv": "ef5a9212fd244049cc02a2c02d73b15b5a992fa117e77054961bf22e26cf7a1d",
        "kinbench-v3/mao2017-3rps-i4/near-singular.csv": "f1957714d7e4144620e66d67a0971c0427504491a154829d8c5fb63ce01852c8",
        "kinbench-v3/mao2017-3rps-i4/printed.csv": "704dec541dcd20ab7ebb3e5bee2b19fcef3c4c3841854ae428a6612144d67249",
        "kinbench-v3/mao2017-3rps-i4/uniform.csv": "09329e2b99b3f4d25fd7103536580f041dd5cf28736b3aeddbfc14a3ec1e5af1",
        "kinbench-v3/mao2017-3rps-i5/boundary.csv": "ba876d39d966674b2afd19da9f78c2625d0518d21a346142ecb1b1e0e7a50a14",
        "kinbench-v3/mao2017-3rps-i5/near-singular.csv": "6045db407bf8a97140384175867278badc3a6a22fe16c8c075d6c8fcfe034e55",
        "kinbench-v3/mao2017-3rps-i5/printed.csv": "704dec541dcd20ab7ebb3e5bee2b19fcef3c4c3841854ae428a6612144d67249",
        "kinbench-v3/mao2017-3rps-i5/uniform.csv": "6e3bd21918188daaee1304e644cda06c3dd7e384c724cabf381b239c50498dea",
        "kinbench-v3/mao2017-3rps-i6/boundary.csv": "fd38c9140e20f9a252889661ca28cccc36570ab7f4da12216927ad7e5b303ff8",
        "kinbench-v3/mao2017-3rps-i6/near-singular.csv": "24fbb2083abe13dc67862819610fa9af9a3a25fb019b58889e8a2ba1e0ffcf2c",
        "kinbench-v3/mao2017-3rps-i6/printed.csv": "704dec541dcd20ab7ebb3e5bee2b19fcef3c4c3841854ae428a6612144d67249",
        "kinbench-v3/mao2017-3rps-i6/uniform.csv": "5636972631b15f53ea338b60a82c9d4d66a44411bfc103cc8820b5ec5b404470",
        "kinbench-v3/mao2017-3rps-i7/boundary.csv": "9cfcd5d6461332741af378db78eb72a47c532e14cf2ee88af827d58ac45f0198",
        "kinbench-v3/mao2017-3rps-i7/near-singular.csv": "eeacad5799903c4d0b8f2ad33ef5dc97afeae8f1b6dc2563bf49903b340174a5",
        "kinbench-v3/mao2017-3rps-i7/printed.csv": "704dec541dcd20ab7ebb3e5bee2b19fcef3c4c3841854ae428a6612144d67249",
        "kinbench-v3/mao2017-3rps-i7/uniform.csv": "56067159f6c6fdbd0e9617489da34899a1f57fcd116c654d05e48656d27a3600",
        "kinbench-v3/mao2017-3rps-i8/boundary.csv": "910b76232934454c28ee4995e7a59b0de51067e579d3631bbf4a6a4935db7b08",
        "kinbench-v3/mao2017-3rps-i8/near-singular.csv": "3bbc706b006dbea5552aa014364836685221985d840df7eca8fe84a0e3cd1313",
        "kinbench-v3/mao2017-3rps-i8/printed.csv": "704dec541dcd20ab7ebb3e5bee2b19fcef3c4c3841854ae428a6612144d67249",
        "kinbench-v3/mao2017-3rps-i8/uniform.csv": "24b99d31327f5232356d204f5ee0d82e70aa8c498e111b06569df0f795af2ca2",
        "kinbench-v3/mao2017-3rps-i9/boundary.csv": "56aa28d3f2e582977b04bc3993a97224a4a0885b161eed311746ec21d7794368",
        "kinbench-v3/mao2017-3rps-i9/near-singular.csv": "65f1663a8cb3314fc415f0fde18eb61ab83a4d814d681284187b97c98ccc57d8",
        "kinbench-v3/mao2017-3rps-i9/printed.csv": "704dec541dcd20ab7ebb3e5bee2b19fcef3c4c3841854ae428a6612144d67249",
        "kinbench-v3/mao2017-3rps-i9/uniform.csv": "797a47ccd6ddf929fa17167328feea004efa4466c2d6b5651e16030b5a7347b8",
        "kinbench-v3/mao2017-3rps/boundary.csv": "f06839ca15bca43882786e708eb5ed812270a723e0b1ad4d55bf3bbd0f049220",
        "kinbench-v3/mao2017-3rps/near-singular.csv": "cfe7baff429cb21e33cca91a93b9f46f805caa01011a0c6b9e76c626fa066593",
        "kinbench-v3/mao2017-3rps/printed.csv": "0939d3cc3902fbb5e434486b25aa6b87514614541c5ef08e858fbdc2690de675",
        "kinbench-v3/mao2017-3rps/uniform.csv": "8dd17a4eafa7f302ec289f222f533c864c60c909bdc64dcdf0a9972629d77c50",
        "kinbench-v3/panda/boundary.csv": "f5a8c6141b2b145c8b18f3b4cc638694801dc4e2c73048f3fc403a3ee356289b",
        "kinbench-v3/panda/near-singular.csv": "98fc710a0f6e552620a264df6a153da053b191531d5b01defc7d21a6d5d2cd18",
        "kinbench-v3/panda/printed.csv": "fb3f1fb8dd3b280c24ccfbaa4026fc2aa3212809f858b186e72e573c5037dc9f",
        "kinbench-v3/panda/uniform.csv": "632ab651246a4df07fefb2d9abc40a98407107b03d11d68ab7bce2485646d547",
        "kinbench-v3/pr2-left-gripper/boundary.csv": "0a1049a9916af2be7918436ffbddd5818df93025dbf83473e93e69bd87749b82",
        "kinbench-v3/pr2-left-gripper/near-singular.csv": "b6eacfd69020fc102c4c0da0c7c19fb5da51d1225b4e9d27f7eb4750d2d802b5",
        "kinbench-v3/pr2-left-gripper/printed.csv": "030f34f5cd4549c827350b7dba4b53b4a579df0b2944050c4d787b57a053e703",
        "kinbench-v3/pr2-left-gripper/uniform.csv": "b6d58e026f13c0e50509841fda4af95f404bb1bd2de8947a3881b84257c8f8a8",
        "kinbench-v3/romeo-left/boundary.csv": "b45f70e64c9d52078752ec0963e8a3fd5be58990cb1c343166f604c7fd91c578",
        "kinbench-v3/romeo-left/near-singular.csv": "6ddf21a680ae87ed8c970961dca2d8bdd3e53af9f49878e810ab327224660a28",
        "kinbench-v3/romeo-left/printed.csv": "a21ed40ccea75852d2372cac94575d2f5ffeb0c16eae4dd64401c7293ca0c8a4",
        "kinbench-v3/romeo-left/uniform.csv": "890f53ff6874c7ede822fee8c55bc3e8e5784409c5e939b322fd94c3373afef8",
        "kinbench-v3/sawyer-mj/boundary.csv": "dea26f47f9debce682a708492c03e662cc0d153f6171cbb1856570da9baa8909",
        "kinbench-v3/sawyer-mj/near-singular.csv": "53ed7b15ea165c26b4aa202da2ba2a8d2059002dd4d65d1521d3efd72a5b8c8d",
        "kinbench-v3/sawyer-mj/printed.csv": "5ddfc90d97019d0e6a8278d427af2d34b195f5895a4d1be3e31021fcd82b6180",
        "kinbench-v3/sawyer-mj/uniform.csv": "fcb79d119928c7c3b4669ddf2965d3aaf6abfa4e37fde1b2af11678d2ea4af05",
        "kinbench-v3/so101/boundary.csv": "1aa48890b6d34afff170a831a6702642cfd3a75bd353b00b2eedc1e0e3db2d0e",
        "kinbench-v3/so101/near-singular.csv": "d344a2643917216444e90f794ec161ecf1596c0de5162fa9e9a1d89b041b9b43",
        "kinbench-v3/so101/printed.csv": "0fe1937ec367cae290f16c17b4abf34666174029d798facf94b522fa2ceb116f",
        "kinbench-v3/so101/uniform.csv": "33415921eaa32ee650b79e3d433087851d0de3dc15cc1b7ac9df9069824b11bc",
        "kinbench-v3/spot-arm-mj/boundary.csv": "7c2f5a058957334840cb9fca63dca9228ecc7bbb9beda2775aca00d2bf3762c4",
        "kinbench-v3/spot-arm-mj/near-singular.csv": "ad900d1c80ebe84a73f1922aa9a3a02c2e64bd3f05f9638435dc5900176cf7bb",
        "kinbench-v3/spot-arm-mj/printed.csv": "b5a1d25c1276d05175902091f7fafee83a681cb16c497bae2a493f5750b75682",
        "kinbench-v3/spot-arm-mj/uniform.csv": "5e56dd62be072f2b2c87302206f6e3309edfe6ee2453374191608684ed981f44",
        "kinbench-v3/talos-left/boundary.csv": "652dc192be958d322c841cc72a35c68838e9b103eaf3331c8817fc3078111f58",
        "kinbench-v3/talos-left/near-singular.csv": "76584505d72f76ab400e5d84447a898f1e4ca160a4fe11f20517b433c9822c96",
        "kinbench-v3/talos-left/printed.csv": "01dcd8453edc8a14ac8d125135ece3003b6142563b836da35cc24068fc057c4a",
        "kinbench-v3/talos-left/uniform.csv": "210a7c46e5fc361cad3527ff62df47da5084ed4108bc675118ac3c037c6f1214",
        "kinbench-v3/tiago-right-mj/boundary.csv": "a0f4bcc3eaa481416991ff889f490566bc6c8f8a8cab71d0b0d74ba5306a64b3",
        "kinbench-v3/tiago-right-mj/near-singular.csv": "26eeeb6fb0b941c6c3823e1982b9d50f4eb03e7b1f46b54fff2954e4b2bbdd43",
        "kinbench-v3/tiago-right-mj/printed.csv": "3a273eff080275e19c0916a2fe338c4ae4c06a6b3622e0d53b68c8e389bf7ed2",
        "kinbench-v3/tiago-right-mj/uniform.csv": "f2695c01f6710f02ca844fe9dacb58698ed7bfee3df81433e39cd44390f68ce1",
        "kinbench-v3/tiago-torso/boundary.csv": "dcdcb6d137fb6a9a1a83319e03df3f02a11b07b658e351fe83ee51eb0c490c44",
        "kinbench-v3/tiago-torso/near-singular.csv": "c55717b26d739483d7153333dbcf981f61151f3d42f418c6d1735e9bad89269f",
        "kinbench-v3/tiago-torso/printed.csv": "aaf812972d219b5dfa1d6d234a6aa99cf291b05901ec5928e57a1d15722bbddf",
        "kinbench-v3/tiago-torso/uniform.csv": "a0ae810e96e2d6af53e84b69f232bc2e2058e96340910fea765633e7669d657e",
        "kinbench-v3/ur10/boundary.csv": "95c354703fd00ffffef27185e3e8f270bcad82767fa4263b4093d5b76bb906e0",
        "kinbench-v3/ur10/near-singular.csv": "18602b10bcbf9f3773d0351d8279e86f03bb95027db8bb4cb84b8cf3043b1adf",
        "kinbench-v3/ur10/printed.csv": "cba884d5ba33d047e9b112ac7b78a9af2ed79033a00644028dc51d5522586671",
        "kinbench-v3/ur10/uniform.csv": "05b04519bfb44c029674e415ef869bcd0c50d1cd611194ae3559f766a9269faf",
        "kinbench-v3/ur3/boundary.csv": "44a4a0b2b54ea809cf62814c6f253f95a8351f28af7875ef80b9ad442c0c33c7",
        "kinbench-v3/ur3/near-singular.csv": "a7ada7446a606a50deb7174e89359711a84b1abcb40b9f0e41e3e19ac3f84576",
        "kinbench-v3/ur3/printed.csv": "cba884d5ba33d047e9b112ac7b78a9af2ed79033a00644028dc51d5522586671",
        "kinbench-v3/ur3/uniform.csv": "c9caef492b2743e91a5a5af0029e42a861b1dda5c662534af77c5c845caece49",
        "kinbench-v3/ur5/boundary.csv": "24e3aeb6e5dac09b71b8fb4f10268345e4154ebaab716e7bf58096af1de78af4",
        "kinbench-v3/ur5/near-singular.csv": "f3117c5340ecc6de36a77f1fa61ac60a30e9609fa29c8d893c1a931435550afd",
        "kinbench-v3/ur5/printed.csv": "cba884d5ba33d047e9b112ac7b78a9af2ed79033a00644028dc51d5522586671",
        "kinbench-v3/ur5/uniform.csv": "435d94e3b699b29f3ced3fd122a2d8e01007cfcecc902b24b70c8201b673c606",
        "kinbench-v3/ur5e-mj/boundary.csv": "1621e700a377f56a3e7844f82493b9b1a1b97a234b2ed108297f8ebc7f9abcdb",
        "kinbench-v3/ur5e-mj/near-singular.csv": "9f2ef42b927d35934caf797afef353f571cd1e694f8f68dc36865b996b09434a",
        "kinbench-v3/ur5e-mj/printed.csv": "cba884d5ba33d047e9b112ac7b78a9af2ed79033a00644028dc51d5522586671",
        "kinbench-v3/ur5e-mj/uniform.csv": "dad44686f7eede3335899857f6b838cc0f913edca9c418e2bf41a112d16ae1d9",
        "kinbench-v3/wang2020-7dof/boundary.csv": "48710bada2f81ffd721e21ce5f21f2a42213982d4e39ce4646c4fb2dfcdfe580",
        "kinbench-v3/wang2020-7dof/near-singular.csv": "0850963bcbf6d29de6b2f223f75e0d2fbfb0b0b4891ce3a1906dcf52bbf172df",
        "kinbench-v3/wang2020-7dof/printed.csv": "a3debf7e8247f002fbc8aa6f22a6264f36e3ed68b1c6a7caa0f5e52baf88cf5a",
        "kinbench-v3/wang2020-7dof/uniform.csv": "269dc7dfd1f2f58644f52e3bdda40b76e28954f498d0ea97c2142e909b9f2f84",
        "kinbench-v3/wu2015-3ppr-i1/boundary.csv": "ceea4c4885d662efb28db2490222df55503af58ab5b7de0858094860090044da",
        "kinbench-v3/wu2015-3ppr-i1/near-singular.csv": "d032e0d43c69201ea1cb1c085c95c487686c96c97ac9a7d0a3c3f9c1f2790f50",
        "kinbench-v3/wu2015-3ppr-i1/printed.csv": "d68693356be6a7efb52ff841eeac9ba9ceb893843dd0e1f5dd22b8175ebfd609",
        "kinbench-v3/wu2015-3ppr-i1/uniform.csv": "a4b22ffe7863d8037736ca31e2c0fac5250a4071bf78a281cb5b89574db6d51c",
        "kinbench-v3/wu2015-3ppr-i10/boundary.csv": "14a8900761479587c3657366a91ab4b5a25e7980eddde30ce724a8f948a61dd8",
        "kinbench-v3/wu2015-3ppr-i10/near-singular.csv": "3c9f200c5593bc588439d8398b024afbad5e4cf2704a9c7f43034b8ad5ddf964",
        "kinbench-v3/wu2015-3ppr-i10/printed.csv": "d68693356be6a7efb52ff841eeac9ba9ceb893843dd0e1f5dd22b8175ebfd609",
        "kinbench-v3/wu2015-3ppr-i10/uniform.csv": "6ed6ba09b825bdd4a549405ce033a67e119d641117060390a839f9aba165bd22",
        "kinbench-v3/wu2015-3ppr-i2/boundary.csv": "847a42af675a368e028da76047472d34033b42414b4fa6c3b9aba1c8dc364728",
        "kinbench-v3/wu2015-3ppr-i2/near-singular.csv": "96d00c676f1fb1d84356cc291dae95648d46419c914b7bf009a618fdb14511de",
        "kinbench-v3/wu2015-3ppr-i2/printed.csv": "d68693356be6a7efb52ff841eeac9ba9ceb893843dd0e1f5dd22b8175ebfd609",
        "kinbench-v3/wu2015-3ppr-i2/uniform.csv": "0a3c1a0a279b25acf0ab5216262aeb35fad63dacdcac458f32d3fd24e45c8156",
        "kinbench-v3/wu2015-3ppr-i3/boundary.csv": "07bf6cb1941bbc73a276574bd7a23d4f592bc697c49f30e3118335461ba2f808",
        "kinbench-v3/wu2015-3ppr-i3/near-singular.csv": "6de1731c116ca64ce178d3178a97f75a38cf8bbbfa10962fa231c75f3bb3a32c",
        "kinbench-v3/wu2015-3ppr-i3/printed.csv": "d68693356be6a7efb52ff841eeac9ba9ceb893843dd0e1f5dd22b8175ebfd609",
        "kinbench-v3/wu2015-3ppr-i3/uniform.csv": "5246c24ca60ed051cdd719e41ffa1db4fbddf545cab34048fda86d26205d3a26",
        "kinbench-v3/wu2015-3ppr-i4/boundary.csv": "8e2eb8611f1e1c25afd53f13b31aa473a289d61f34781e9a7702e2283591c731",
        "kinbench-v3/wu2015-3ppr-i4/near-singular.csv": "415dbb255f7d248a9bca666563bb680e6234ddb03dcfcca0c436fc070088e4e5",
        "kinbench-v3/wu2015-3ppr-i4/printed.csv": "d68693356be6a7efb52ff841eeac9ba9ceb893843dd0e1f5dd22b8175ebfd609",
        "kinbench-v3/wu2015-3ppr-i4/uniform.csv": "ca739bf6e1fa869c13dcb26a6ad7feed43da2a2788952e920060cda9cdbd34d0",
        "kinbench-v3/wu2015-3ppr-i5/boundary.csv": "620eadd36a54631d1688ebd4c234e493bd097605b014f4742d263f2b7f60a582",
        "kinbench-v3/wu2015-3ppr-i5/near-singular.csv": "e88513c6c70349e2baaf5fac51043022ebd4ac6142f88bdae103c22e6c64bb8b",
        "kinbench-v3/wu2015-3ppr-i5/printed.csv": "d68693356be6a7efb52ff841eeac9ba9ceb893843dd0e1f5dd22b8175ebfd609",
        "kinbench-v3/wu2015-3ppr-i5/uniform.csv": "778beb3dc99698f0f97a439f0f1a6087b198c8397f0ad25ea873d86824e21313",
        "kinbench-v3/wu2015-3ppr-i6/boundary.csv": "ef24ecb3d64119a87c38ad104d2e121eac53a0fc0c69aa0af9759863035df8fa",
        "kinbench-v3/wu2015-3ppr-i6/near-singular.csv": "f257d040153d89cc7d16d023270603fe3cd0c4b1efa63d911da1cc75e303be29",
        "kinbench-v3/wu2015-3ppr-i6/printed.csv": "d68693356be6a7efb52ff841eeac9ba9ceb893843dd0e1f5dd22b8175ebfd609",
        "kinbench-v3/wu2015-3ppr-i6/uniform.csv": "43d510c50e893c344d224e5fb234b19a8b6d09aa54ee21a3e46a9ae7b72a5116",
        "kinbench-v3/wu2015-3ppr-i7/boundary.csv": "011e521830689f78015898d3aedf3d5fcb3dda5e991cfaab32db1a70b66518ee",
        "kinbench-v3/wu2015-3ppr-i7/near-singular.csv": "ac6089d11ace45a09fe22702aaeb05fd639e9e868df5af305782d4c24c272101",
        "kinbench-v3/wu2015-3ppr-i7/printed.csv": "d68693356be6a7efb52ff841eeac9ba9ceb893843dd0e1f5dd22b8175ebfd609",
        "kinbench-v3/wu2015-3ppr-i7/uniform.csv": "56be68043f34ab1068fb01ee5c308ea6f3383b6fe2bc34dc391cf9210408e469",
        "kinbench-v3/wu2015-3ppr-i8/boundary.csv": "c7a25361af15d431f0abef80c92062844c968070b1f2550cc32b843a27289715",
        "kinbench-v3/wu2015-3ppr-i8/near-singular.csv": "96b4fd30d2eeb347c35a6bab599aa3a0e88b2ceef0d6d9aa6bd4ed117bb0d2ad",
        "kinbench-v3/wu2015-3ppr-i8/printed.csv": "d68693356be6a7efb52ff841eeac9ba9ceb893843dd0e1f5dd22b8175ebfd609",
        "kinbench-v3/wu2015-3ppr-i8/uniform.csv": "633ef9dbe0ec00ebbc6bdf66b916690ce27fd186198658c1e658619dd3fc9b9c",
        "kinbench-v3/wu2015-3ppr-i9/boundary.csv": "d8e47ff28ad5b1e8abb374feacc8e45a594de6cdb6d1de097e92a64050bd0817",
        "kinbench-v3/wu2015-3ppr-i9/near-singular.csv": "53d4f13a3af92d80429fc5afff4750c207aae362b522779e05c696041cf64b99",
        "kinbench-v3/wu2015-3ppr-i9/printed.csv": "d68693356be6a7efb52ff841eeac9ba9ceb893843dd0e1f5dd22b8175ebfd609",
        "kinbench-v3/wu2015-3ppr-i9/uniform.csv": "79e156c1c6cb1a11506b11c88b01bf31aba813418633da94b3250d807af4939b",
        "kinbench-v3/wu2015-3ppr/boundary.csv": "6c0d5cb17a551d2fc32bb9a026a42a119c20ac1e63e2ad366f61851ec6ed40a3",
        "kinbench-v3/wu2015-3ppr/near-singular.csv": "a37e994cad3d7505a022d9cc24892198f7a0dab889e919ba53139f57458469f5",
        "kinbench-v3/wu2015-3ppr/printed.csv": "7e9103b825c3d90e08949e0c7fc4011bea1e533b674055cbc4f1a519b49f0bd6",
        "kinbench-v3/wu2015-3ppr/uniform.csv": "9d19d0151750bef8872bcc4ec7461471f284ef7277533f3b73cea68fb819653b",
        "kinbench-v3/xarm7/boundary.csv": "0ca20ecd366dcbd62cc0a8f075353a7926aea0a8e39feddd243b32fff41f8f6b",
        "kinbench-v3/xarm7/near-singular.csv": "3513c94c39826f0970e5bda17ac47d6f01531ccc39c706e80d9559e24c8397a9",
        "kinbench-v3/xarm7/printed.csv": "2dfb24318241ace8ee776a91030025d3dbe4e7c7695fe3324276b37d8086f731",
        "kinbench-v3/xarm7/uniform.csv": "b9b28dbdd292179b328581e78fe667fbececc49d944a7d611a1c7494609d60b8",
        "kinbench-v3/z1/boundary.csv": "a09dda6ba4dbd9ac3a3cd0f03380c6b48cdfb6751ad7c4d6fa0a8aaf507b72e2",
        "kinbench-v3/z1/near-singular.csv": "5a3aefa38bcade96b978ac823973c666b21b4d70fecd318b9a711a43fe5f10e8",
        "kinbench-v3/z1/printed.csv": "38e768d666589b2abcca4da7fe865792b6b83b56bc26759210ebe6a6af529948",
        "kinbench-v3/z1/uniform.csv": "ae770d07b069d3e2a6cc96a05c61345889fd6150a2f6a5df24589681c12337d5",
        "robots/baxter-left.urdf": "3a2951321fcdcfe470e9fb40d1dd6f831250a1e9c6e37e30d99b22d213b241df",
        "robots/baxter-right-mj.xml": "c1eba796574fe69bf7f1a292a642ea53c1a66b3acd511545d23944c317c1d824",
        "robots/g1-left.urdf": "beb11b590f859a3bdd3c21615b48fda1342f8b215cad962276a7396e2179c79f",
        "robots/gr1-left-mj.xml": "24dd9bc7e21de964c5949c17c1cd631b37f1bb7c9dd66a8116c26c181af497cc",
        "robots/icub-left.urdf": "c3beffb812fe327b24ae7ec000913936bdedb26bd65d6b043ac983e3d2a9a819",
        "robots/iiwa-mj.xml": "d99999f81c9ff2cfa27076dd5db2056ea5c2b0234a9f4f3a56d9f88be3c790f4",
        "robots/jaco-mj.xml": "2a81427f423a07cd03b685b233688607194a270949040c8a1a7cc5c144c48688",
        "robots/kinova-j2s6s200.urdf": "984f244dc42fdf7426f689c45b8d9f19da97cf1d054b9e0503dddb56c033ea9f",
        "robots/kinova3-mj.xml": "8b50001a6c3fa6b00f7a79085de8c8507a501e4d2ea910922bd7503ad0aad24b",
        "robots/panda.urdf": "798c686857026fd29ec7d096eb90299dc149407b63b8cbfac37cf447f12a4f73",
        "robots/pr2-left-gripper.urdf": "85cafd4c544e309eca782537148d28ff3814133ab022f6442c6a319c8fb5527c",
        "robots/romeo-left.urdf": "e5174204afd57f155a0b2d1c7474895ea28880678ad1cbdac05781aa04934a9a",
        "robots/sawyer-mj.xml": "b12d675446745c6594db66e8f5ecf34e98ba85366993486e3375c6dc0b156cbe",
        "robots/so101.urdf": "2c5b2d7859f5f0d09a89a47e82cd71571491733d971459c1c2aeee6df1e998e0",
        "robots/spot-arm-mj.xml": "5687fb0698cc1a7011883539240f769d6951760947eebb04b355010e779aeeab",
        "robots/talos-left.urdf": "6532169b1bf2609318e30181ef572e9e805ec1da83ef6f89b85e5bcf238c6648",
        "robots/tiago-right-mj.xml": "acd72f0a46b2fbd3e20e4618455119e3c841e28bcfc6b0008daf94184cca2cca",
        "robots/tiago-torso.urdf": "9bb7d4908b8d851ec6cc96d07d639f7483b2f77dd3e2d7d49fddc70598318b17",
        "robots/ur10.urdf": "0190a8455664f3d94acebddf73837e2b078e6f78d3dc3506698239fd45ead487",
        "robots/ur3.urdf": "311e69e96ce9452b43876646fafa50b83f92661daef89d7cee97aff51adcebe1",
        "robots/ur5.urdf": "0550334fd0085f11e71945520d0180a7c224e1002e7723ff8e26ae30bcc9852c",
        "robots/ur5e-mj.xml": "fd0c79c40314595daa151b94a58fdb9b7765e1cc9e19db01579cc2a3878dc01c",
        "robots/xarm7.urdf": "2b99c1d4657a71c576b69c2537be21a9d4358b49bf02f0af1b1e8da569bd9762",
        "robots/z1.urdf": "08344afd14d43bb1fc2cb7249f8b90ddef756991ff64c9a9cee9ef0cb619ae38",
    }),
    # the paths track's frozen path set (fkopt.kinbench.paths; python -m fkopt.kinbench.freeze paths SUITE.yaml):
    # checked by check_folder_release (its fitness field is unused: a path set holds joints only)
    "kinbench-v3-paths": Release(fitness=1, files={
        "kinbench-v3-paths/iiwa-mj.csv": "81973a1acdc8293206834c9adcbd197f5ef938442801ae5e264eda86f08b8a2d",
        "kinbench-v3-paths/kinova-j2s6s200.csv": "5423b8a5027f2f7de224823848a7046692ad3baec6ee2027384355ba11afbc1a",
        "kinbench-v3-paths/manifest.json": "6ff061dff96d6a36df94f90bf87f6dcab49f7c8ddf3ded649891370d384ecf9f",
        "kinbench-v3-paths/panda.csv": "850e09ffd0038d0a118992bfe538c72b457d52c14e142de13d1897d5dc52e92c",
        "kinbench-v3-paths/ur5.csv": "a90cec4919ab9c8f2775895fc31741ae1e3c334975519a46b6c92fd8de2e6b40",
        "kinbench-v3-paths/z1.csv": "51460f5fc2f17b0c79feda8d384f41fb252715b1f64f57aae2549b500e6f4a46",
    }),
}




def _base(config, files) -> Path:
    """Where the suite's relative files are: ``files``, else the suite file's folder."""
    base = files if files is not None else files_folder(config)
    return Path(base if base is not None else ".")


def problem_files(config) -> list[str]:
    """The files the suite's problems read (mechanism file fields), relative to the suite's folder."""
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
    expected = _check_files(name, release, base, base / config.pose_sets, new)
    for rel in problem_files(config):
        if rel not in expected:
            raise FkoptError(f"{base / rel}: problem file not part of released {name}{new}")


def _check_files(name: str, release: Release, base: Path, folder: Path, new: str) -> dict[str, str]:
    """Refuse (one line) a file of released ``name`` in ``folder`` (relative to ``base``) that is
    missing, changed or added; the expected {path: SHA-256}, the folder's name put for the
    version's (a copy may be named otherwise)."""
    expected = {(f"{folder.name}/{k.split('/', 1)[1]}" if k.startswith(name + "/") else k): v
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
    return expected


def check_folder_release(name: str, base: Path, folder: Path) -> None:
    """A frozen data folder of a track (``tracks.paths.path_set``) named as a released version
    (:data:`RELEASES`): every file as released (nothing to check for an unreleased name)."""
    release = RELEASES.get(name)
    if release is not None:
        _check_files(name, release, Path(base), Path(folder), "; a changed set must name itself a new version "
                     "(a new folder)")


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

