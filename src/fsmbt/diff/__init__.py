"""``fsmbt diff``: every behavioural difference of two models and the edit that caused it
(docs/diff.md).

``diff_models(old, new)`` pairs the two models as the verifier does, lists every group of
distinguishing runs with a shortest witness (``behaviour.py``, on the native checker's product)
and the structural edit script (``structure.py``); ``report.py`` writes it as Markdown, JUnit
or JSON, ``picture.py`` draws NEW with the changes marked. ``diff_files`` reads the two files
through ``fsmbt.api.load`` first. This package sits above ``api`` and below the interfaces.
"""

from __future__ import annotations

from fsmbt.diff.behaviour import DEFAULT_MAX_GROUPS, BehaviourDiff, Divergence, behaviour_diff
from fsmbt.diff.changes import Changes, diff_changes
from fsmbt.diff.compare import diff_files, diff_models
from fsmbt.diff.picture import diff_dot, write_diff_picture
from fsmbt.diff.report import DiffReport, divergence_text, to_junit, to_markdown
from fsmbt.diff.structure import EditOp, edit_script

__all__ = [
    "BehaviourDiff",
    "Changes",
    "diff_changes",
    "DEFAULT_MAX_GROUPS",
    "DiffReport",
    "Divergence",
    "EditOp",
    "behaviour_diff",
    "diff_dot",
    "diff_files",
    "diff_models",
    "divergence_text",
    "edit_script",
    "to_junit",
    "to_markdown",
    "write_diff_picture",
]
