"""Where the shared corpus (real files written by other people, read-only) is: ``FSMBT_CORPUS``,
else ``<repo>/../shared/corpus`` exactly as CI spells it - not resolved, so the tests see the
path a user gives, with its ``..``, and any code that compares a resolved path with the given
one fails here rather than only on CI."""

from __future__ import annotations

import os
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
CORPUS = Path(os.environ.get("FSMBT_CORPUS", REPO / ".." / "shared" / "corpus"))

#: benchmarks/corpus_coverage.py's "profiles" setting, as a user of each project types it:
#: the node libraries of node_libraries/ by source folder and by file-name prefix.
NODE_LIBRARIES = REPO / "node_libraries"
_LIBRARIES_BY_SOURCE = {"bt/btcpp_tutorials": ("btcpp_tutorials.yaml",)}
_LIBRARIES_BY_PREFIX = {
    "IntelligentRoboticsLabs_robocup2020_": ("robocup2020.yaml",),
    "julienbayle_stardust_": ("stardust.yaml",),
    "kmi-robots_hans-ros-supervisor_": ("hans_ros_supervisor.yaml",),
}


def profile_options(path: Path) -> dict[str, object]:
    """The reader options of the corpus' "profiles" setting for one BT file of the corpus
    (docs/corpus.md): ``--nodes nav2,moveit_pro`` and the project's node library, Nav2's node
    models for the Nav2 trees, ``--include-root`` for BehaviorTree.CPP's own test files."""
    rel = path.relative_to(CORPUS)
    source = "/".join(rel.parts[:2])
    names = list(_LIBRARIES_BY_SOURCE.get(source, ()))
    for prefix, files in _LIBRARIES_BY_PREFIX.items():
        if path.name.startswith(prefix):
            names += files
    options: dict[str, object] = {
        "nodes": ["nav2", "moveit_pro", *(str(NODE_LIBRARIES / n) for n in names)]
    }
    if source == "bt/nav2":
        options["node_models"] = [str(CORPUS / "bt" / "nav2" / "models" / "nav2_tree_nodes.xml")]
    if source == "bt/btcpp":
        options["include_root"] = str(CORPUS / source)
    return options
