"""Does BehaviorTree.CPP load a tree fsmbt wrote? The load check of every written BT.

Rule (docs/semantics.md §5, "Every written tree loads"): a behavior tree ``convert`` writes for
BehaviorTree.CPP is loaded in BehaviorTree.CPP 4.8.2 before it is reported, with every node of
its ``<TreeNodesModel>`` registered with its declared ports; a refusal is an error, never a
verdict. Two ways, the first one available:

1. the C++ build (``fsmbt doctor --install btcpp``): ``btcpp_load.cpp`` next to this module,
   compiled on first use against the cached library into
   ``bin/fsmbt_btcpp_load-<sha256 of the source, 16 hex>`` (a changed source is rebuilt, a stale
   binary never run), given the file and its declarations (``KIND ID dir:port ...`` lines); it
   calls ``createTreeFromFile``: BehaviorTree.CPP's own XML parser (tinyxml2, with its nesting
   limit), port checks, SubTree instantiation;
2. without that build, behaviortreepy (the same engine, in process): it cannot declare ports,
   so declared nodes are registered port-less, their attributes are dropped from the copy it
   reads, and a declared control node is read as a ``Sequence`` (behaviortreepy cannot register
   controls); the result names the engine "behaviortreepy ... ports stripped" so a summary says
   which check ran.

Costs: the first C++ check compiles the program (about 10 s on one core); each check is one
process start plus BehaviorTree.CPP's load, O(file size) (a 100 000-state LEBT: seconds).
"""

from __future__ import annotations

import json
import re
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from fsmbt.cache import BTCPP_VERSION
from fsmbt.model.errors import FsmbtError, SourceLocation
from fsmbt.semantics.engines.btcpp_tool import ToolBuildError, build_tool, tool_path

SOURCE = Path(__file__).resolve().with_name("btcpp_load.cpp")
ENGINE_CPP = f"BehaviorTree.CPP {BTCPP_VERSION}"
ENGINE_PY = f"BehaviorTree.CPP {BTCPP_VERSION} through behaviortreepy (ports stripped)"
_KINDS = ("Action", "Condition", "Control", "Decorator")
_DIRECTIONS = {"input_port": "input", "output_port": "output", "inout_port": "inout"}
# deep documents are what this check is for: lxml's own depth limit must not answer first
_PARSER = etree.XMLParser(huge_tree=True, resolve_entities=False, no_network=True, load_dtd=False)
_LINE = re.compile(r"(?:Line number|line)[= ]+(\d+)", re.IGNORECASE)
#: tinyxml2's nesting limit in BehaviorTree.CPP 4.8.2 (``TINYXML2_MAX_ELEMENT_DEPTH``); its
#: refusal names line 1, so the line of the first element that deep is found here instead.
TINYXML2_MAX_DEPTH = 500


class TreeLoadError(FsmbtError):
    """A written behavior tree that BehaviorTree.CPP refuses to load (located at the file and,
    when the engine says it, the line)."""


@dataclass(frozen=True)
class LoadCheck:
    """One load check's answer.

    Attributes:
        engine: which check ran (``ENGINE_CPP`` or ``ENGINE_PY``).
        loaded: whether the engine built the tree.
        error: the engine's refusal, one line ("" when loaded).
        line: the line it names, when it names one.
        nodes: nodes the engine instantiated (C++ check only).
    """

    engine: str
    loaded: bool
    error: str = ""
    line: int | None = None
    nodes: int | None = None

    def summary(self) -> str:
        """``loads in BehaviorTree.CPP 4.8.2: yes`` (or ``no (...)``)."""
        return f"loads in {self.engine}: " + ("yes" if self.loaded else f"no ({self.error})")

    def raise_if_refused(self, file: str | None) -> None:
        """``TreeLoadError`` located at ``file`` (and the engine's line) when not loaded."""
        if self.loaded:
            return
        raise TreeLoadError(
            f"the written result does not load in {self.engine}: {self.error}",
            location=SourceLocation(file or "<result>", self.line),
        )


def program_path() -> Path:
    """Where the program built from this module's C++ source is (may not exist)."""
    return tool_path(SOURCE, "fsmbt_btcpp_load")


def find_program(*, build: bool = True) -> Path | None:
    """The compiled check, compiled first when ``build`` and the library is there; ``None``
    when the library is not built, no C++ compiler is found or compiling fails."""
    try:  # a read-only cache, a refused source or a compiler that hangs: no C++ check
        return build_tool(SOURCE, "fsmbt_btcpp_load", build=build)
    except (ToolBuildError, OSError, subprocess.TimeoutExpired):
        return None


def declarations(root: etree._Element) -> str:
    """The program's input for a file's ``<TreeNodesModel>``: ``KIND ID dir:port...`` lines."""
    lines: list[str] = []
    for container in root.iter("TreeNodesModel"):
        for entry in container:
            if not isinstance(entry.tag, str) or entry.tag not in _KINDS or not entry.get("ID"):
                continue
            ports = [
                f"{_DIRECTIONS[str(p.tag)]}:{p.get('name')}"
                for p in entry
                if isinstance(p.tag, str) and p.tag in _DIRECTIONS and p.get("name")
            ]
            lines.append(" ".join([str(entry.tag), str(entry.get("ID")), *ports]))
    return "\n".join(lines) + "\n"


def _refused(engine: str, message: str, root: etree._Element | None = None) -> LoadCheck:
    message = " ".join(message.split())[:600]
    found = _LINE.search(message)
    line = int(found.group(1)) if found else None
    if root is not None and "DEPTH_EXCEEDED" in message:
        line = _too_deep_line(root) or line
    return LoadCheck(engine, False, message, line)


def _too_deep_line(root: etree._Element) -> int | None:
    """The source line of the first element nested ``TINYXML2_MAX_DEPTH`` levels deep (the
    root element = 1), found without recursion; ``None`` when there is none."""
    stack = [(root, 1)]
    while stack:
        element, level = stack.pop()
        if level >= TINYXML2_MAX_DEPTH:
            return element.sourceline
        stack.extend(
            (child, level + 1) for child in reversed(element) if isinstance(child.tag, str)
        )
    return None


def _cpp_check(program: Path, text: str, root: etree._Element, timeout: float) -> LoadCheck | None:
    """The compiled check's answer; ``None`` when the program itself cannot run (its shared
    library gone, not executable): that is no answer about the tree."""
    with tempfile.TemporaryDirectory(prefix="fsmbt-load-") as folder:
        tree_file = Path(folder) / "tree.xml"
        tree_file.write_text(text, encoding="utf-8")
        try:
            done = subprocess.run(
                [str(program), str(tree_file)],
                input=declarations(root),
                capture_output=True,
                text=True,
                timeout=timeout,
                check=False,
            )
        except subprocess.TimeoutExpired:
            return _refused(ENGINE_CPP, f"the load did not finish within {timeout:g} s")
        except OSError:
            return None
    if done.returncode == 0:
        answer = json.loads(done.stdout.strip().splitlines()[-1])
        return LoadCheck(ENGINE_CPP, True, nodes=int(answer["nodes"]))
    if done.returncode < 0:  # killed by a signal: a crash of the loader is a refusal too
        return _refused(ENGINE_CPP, f"the loader stopped with signal {-done.returncode}")
    if done.returncode != 1 or not done.stderr.startswith("error: "):
        return None  # not the program's own answer (the dynamic loader's, a usage error)
    return _refused(ENGINE_CPP, done.stderr.strip().removeprefix("error: "), root)


def _never_ticked(*_args: object) -> object:  # pragma: no cover - the check only loads
    raise AssertionError("a load check never ticks")


def _python_check(root: etree._Element) -> LoadCheck:
    """behaviortreepy, ports stripped (module docstring, way 2)."""
    import behaviortreepy as btpy  # the pinned dependency; imported only when it is needed

    declared: dict[str, str] = {}
    for container in root.iter("TreeNodesModel"):
        for entry in container:
            if isinstance(entry.tag, str) and entry.tag in _KINDS and entry.get("ID"):
                declared[str(entry.get("ID"))] = str(entry.tag)
    factory = btpy.BehaviorTreeFactory()
    custom = declared
    for tree in root.iter("BehaviorTree"):
        for element in tree.iter():
            if not isinstance(element.tag, str):
                continue
            kind = custom.get(element.tag)
            if kind is None and element.tag in _KINDS:
                kind = custom.get(str(element.get("ID")))
            if kind is None:
                continue
            keep = {k: v for k, v in element.attrib.items() if k in ("name", "ID")}
            element.attrib.clear()
            element.attrib.update(keep)
            if kind == "Control":
                element.tag = "Sequence"
                element.attrib.pop("ID", None)
    registrars = {
        "Action": factory.register_simple_action,
        "Condition": factory.register_simple_condition,
        "Decorator": factory.register_simple_decorator,
    }
    for name, kind in custom.items():
        if kind in registrars:
            try:
                registrars[kind](name, _never_ticked)
            except Exception:  # a built-in's name: the built-in stays, as in BehaviorTree.CPP
                continue
    for models in list(root.iter("TreeNodesModel")):
        parent = models.getparent()
        if parent is not None:
            parent.remove(models)
    try:
        factory.create_tree_from_text(etree.tostring(root, encoding="unicode"))
    except Exception as exc:  # behaviortreepy raises RuntimeError subclasses of its own
        return _refused(ENGINE_PY, str(exc), root)
    return LoadCheck(ENGINE_PY, True)


def check_loads(text: str, *, timeout: float = 600.0, build: bool = True) -> LoadCheck:
    """Load ``text`` (a BehaviorTree.CPP v4 document) in BehaviorTree.CPP (module docstring).

    Args:
        text: the document as it is written.
        timeout: seconds the C++ loader may take.
        build: compile the C++ check when the library is built and the program is not.

    Returns:
        The ``LoadCheck`` (C++ when the build is there and runs, else behaviortreepy); a load
        that takes longer than ``timeout`` is a refusal.
    """
    try:
        root = etree.fromstring(text.encode("utf-8"), _PARSER)
    except etree.XMLSyntaxError as exc:
        return _refused(ENGINE_CPP, f"not XML: {exc}")
    program = find_program(build=build)
    if program is not None:
        answer = _cpp_check(program, text, root, timeout)
        if answer is not None:
            return answer
    return _python_check(root)
