"""The C++ skeleton of a behavior tree: BehaviorTree.CPP 4 leaf classes, registration, main.

For every leaf type of the tree (``leaves.leaf_kinds``):

- ``generated/fsmbt_nodes.hpp``: one base class per type - ``BT::StatefulActionNode`` for an
  Action, ``BT::ConditionNode`` for a Condition - with ``providedPorts()`` from the model,
  ``label()`` (the leaf's ``name``: the state's label) and ``parameters()`` (its ports as the
  tree writes them). ROS 2 leaves get ``BT::RosActionNode<T>`` / ``BT::RosServiceNode<T>``
  bases (behaviortree_ros2) in ``generated/fsmbt_ros_nodes.hpp``.
- ``nodes/<type>.hpp``: the user's class, derived from the base, with a working default body
  (log and succeed); written once, never rewritten.
- ``generated/register_nodes.hpp``: ``registerNodes(factory)`` (and
  ``generated/register_ros_nodes.hpp``: ``registerRosNodes(factory, node)``).
- ``main.cpp`` and ``CMakeLists.txt`` (written once): load ``tree.xml`` (a copy of the
  tree, rewritten) and tick it; ``main_ros.cpp`` when the tree has ROS 2 leaves.

Cost: O(leaf types x ports) to render.
"""

from __future__ import annotations

import re

from fsmbt.model.bt import BTDocument
from fsmbt.runtime.skeleton.files import SkeletonFile
from fsmbt.runtime.skeleton.leaves import LeafKind
from fsmbt.runtime.skeleton.render import render

NAMESPACE = "bt_nodes"
BASE_HEADER = "fsmbt_nodes.hpp"
ROS_BASE_HEADER = "fsmbt_ros_nodes.hpp"
ROS_REGISTER_HEADER = "register_ros_nodes.hpp"


def project_name(text: str) -> str:
    """A CMake target name from a file stem (``pick_place_bt``)."""
    name = re.sub(r"[^0-9A-Za-z_]+", "_", text).strip("_") or "bt"
    return name if not name[0].isdigit() else "bt_" + name


def user_file(leaf: LeafKind) -> str:
    return f"nodes/{leaf.file_stem}.hpp"


def cpp_files(
    doc: BTDocument, leaves: list[LeafKind], tree_text: str, *, source: str, project: str
) -> list[SkeletonFile]:
    """Every file of the C++ skeleton (see the module doc)."""
    del doc  # the leaves carry all that is rendered; the tree travels as its text
    plain = [leaf for leaf in leaves if leaf.ros is None]
    ros = [leaf for leaf in leaves if leaf.ros is not None]
    common: dict[str, object] = {
        "source": source,
        "namespace": NAMESPACE,
        "project": project,
        "leaves": leaves,
        "plain": plain,
        "ros": ros,
        "ros_register_header": ROS_REGISTER_HEADER,
        "ros_headers": sorted({leaf.ros.header for leaf in ros if leaf.ros is not None}),
        "ros_packages": sorted({leaf.ros.package for leaf in ros if leaf.ros is not None}),
    }
    files = [
        SkeletonFile("tree.xml", tree_text, user=False),
        SkeletonFile(f"generated/{BASE_HEADER}", render("cpp_nodes.hpp.j2", **common), False),
        SkeletonFile(
            "generated/register_nodes.hpp",
            render("cpp_register.hpp.j2", base_header=BASE_HEADER, **common),
            False,
        ),
    ]
    if ros:
        files.append(
            SkeletonFile(
                f"generated/{ROS_BASE_HEADER}", render("cpp_ros_nodes.hpp.j2", **common), False
            )
        )
        files.append(
            SkeletonFile(
                f"generated/{ROS_REGISTER_HEADER}",
                render("cpp_register_ros.hpp.j2", **common),
                False,
            )
        )
    for leaf in leaves:
        header = ROS_BASE_HEADER if leaf.ros is not None else BASE_HEADER
        files.append(
            SkeletonFile(
                user_file(leaf),
                render("cpp_user_node.hpp.j2", leaf=leaf, base_header=header, **common),
                True,
            )
        )
    files.append(SkeletonFile("main.cpp", render("cpp_main.cpp.j2", **common), True))
    if ros:
        files.append(SkeletonFile("main_ros.cpp", render("cpp_main_ros.cpp.j2", **common), True))
    files.append(SkeletonFile("CMakeLists.txt", render("cpp_CMakeLists.txt.j2", **common), True))
    return files
