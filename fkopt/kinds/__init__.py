"""The kinds of config file (floor 4 of docs/design.md), each a config model, a plan and its own
outputs, registered with the engine (:data:`fkopt.run.kinds.KINDS`) as a
:class:`~fkopt.run.tasks.Kind` of function objects when imported: :mod:`.experiment` (listed poses
of one problem), :mod:`.study` (a generated pose set of one mechanism), :mod:`.assembly` (every
assembly mode). kinbench's suites (:mod:`fkopt.kinbench.kind`) register the same way. No kind
imports another.
"""
from fkopt.kinds.experiment import kind as experiment_kind
from fkopt.kinds.study import kind as study_kind
from fkopt.kinds.assembly import kind as assembly_kind

__all__ = ["experiment_kind", "study_kind", "assembly_kind"]
