"""``fsmbt testgen``: a behaviour test suite from a specification (docs/testgen.md).

``generate(spec)`` gives the cases covering every transition of the specification's
leaf-execution machine (``cases.py``); ``write_suite`` writes them with a pytest file that runs
them on py_trees and BehaviorTree.CPP (``write.py``); ``run_case`` runs one case on any engine
and ``mutation_score`` counts the checker's mutants of the tree the suite kills
(``runner.py``). This package sits above ``api``.
"""

from __future__ import annotations

from fsmbt.testgen.cases import Case, Suite, generate
from fsmbt.testgen.runner import kills, mutation_score, run_case
from fsmbt.testgen.write import write_suite

__all__ = ["Case", "Suite", "generate", "kills", "mutation_score", "run_case", "write_suite"]
