"""Where the Python module an import names lives, in a ROS workspace (never imported).

FlexBE behaviours embed other behaviours (``from pkg.walk_sm import WalkSM``) and use states
of other packages (``from pkg_states.log_state import LogState``). In a ROS workspace a module
``pkg.mod`` is the file ``mod.py`` of the ROS package ``pkg``, which sits in one of the layouts
catkin (ROS 1) and ament_python (ROS 2) use: ``<pkg>/src/<pkg>/mod.py``, ``<pkg>/<pkg>/mod.py``
or ``<pkg>/mod.py`` (a folder named after the package), found in a folder above the importing
file. ROS package names are unique in a workspace, so the package's own folder is the only
file that can be meant.

Rules (docs/formats/flexbe.md, "Embedded behaviours"):
- the importing file's own package first: when its folder (or the folder holding its
  ``src``) is named after the imported package, ``mod.py`` beside it;
- then the package's folder in the layouts above, looked for in each folder above the
  importing file, at most ``MAX_LEVELS_UP`` levels up (a workspace's ``src/`` holding the
  repositories holding the packages);
- then ``mod.py`` beside the importing file (a folder that is not a package, e.g. behaviours
  gathered by hand);
- never a file of another package, and never a file found by its content alone.
Every path looked at is recorded with ``note_read`` (a cached result is invalidated when such
a file appears). Costs: O(levels × layouts) file-system checks per lookup.
"""

from __future__ import annotations

from pathlib import Path

from fsmbt.model.files import note_read

#: How far above the importing file a package folder is looked for.
MAX_LEVELS_UP = 5


def find_module_file(importer: Path, module: str | None) -> Path | None:
    """The file of ``module`` (``pkg.sub.mod``) as seen from ``importer``, or ``None``.

    Args:
        importer: the file whose import names the module.
        module: the dotted module path (``None``: not known, nothing is found).

    Returns:
        The module's file, when one of the rules above finds it.
    """
    if not module:
        return None
    parts = module.split(".")
    package, inner = parts[0], parts[1:]
    if not inner:
        return None
    relative = Path(*inner[:-1], f"{inner[-1]}.py")
    folder = importer.parent
    candidates: list[Path] = []
    if folder.name == package:
        candidates.append(folder / relative)
    above = folder
    for _ in range(MAX_LEVELS_UP):
        for layout in (
            Path(package, "src", package),
            Path(package, package),
            Path(package),
        ):
            candidates.append(above / layout / relative)
        if above.parent == above:
            break
        above = above.parent
    if len(inner) == 1:
        candidates.append(folder / relative)
    for candidate in candidates:
        note_read(candidate)
        if candidate.is_file():
            return candidate
    return None
