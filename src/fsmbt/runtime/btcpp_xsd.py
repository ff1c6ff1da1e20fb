"""BehaviorTree.CPP's own XSD for a written file, and the check of the file against it.

Why: a BT file fsmbt writes must be one BehaviorTree.CPP 4.8.2 and Groot2 accept. The schema is
not ours: ``BT::writeTreeXSD`` generates it from a factory holding BehaviorTree.CPP's built-ins
plus the nodes the file's own ``<TreeNodesModel>`` declares (with their ports).
``cpp/xsd/fsmbt_btcpp_xsd.cpp`` is that factory: a tiny program compiled against the cached
BehaviorTree.CPP build (``fsmbt doctor --install btcpp``), cached as
``bin/fsmbt_btcpp_xsd-<sha256 of its source, 16 hex>`` next to the driver, so a changed source
is rebuilt and a stale binary is never used. docs/formats/btcpp.md ("Checked against
BehaviorTree.CPP's XSD") lists what that XSD cannot express.

Costs: the first call compiles the program (about 10 s on one core); each check runs it once
per distinct ``<TreeNodesModel>`` (memoised) and validates with lxml in O(file size).
"""

from __future__ import annotations

import subprocess
from functools import lru_cache
from pathlib import Path

from lxml import etree

from fsmbt.runtime.cpp import PACKAGE_DIR, CppRuntimeError
from fsmbt.semantics.engines.btcpp_load import declarations
from fsmbt.semantics.engines.btcpp_tool import ToolBuildError, build_tool, tool_path

XSD_SOURCE = PACKAGE_DIR / "xsd" / "fsmbt_btcpp_xsd.cpp"


def program_path() -> Path:
    """Where the program built from this package's source is (may not exist)."""
    return tool_path(XSD_SOURCE, "fsmbt_btcpp_xsd")


def find_program(*, build: bool = True) -> Path | None:
    """The program, compiled first when ``build`` and the library is there; ``None`` when the
    library is not built or no C++ compiler is found (``CppRuntimeError`` when it does not
    compile)."""
    try:
        return build_tool(XSD_SOURCE, "fsmbt_btcpp_xsd", build=build)
    except ToolBuildError as exc:
        raise CppRuntimeError(str(exc)) from exc


@lru_cache(maxsize=256)
def _schema(program: str, declared: str) -> etree.XMLSchema:
    done = subprocess.run(
        [program], input=declared, capture_output=True, text=True, timeout=60, check=False
    )
    if done.returncode != 0:
        raise CppRuntimeError(f"fsmbt_btcpp_xsd failed: {done.stderr.strip()[:400]}")
    return etree.XMLSchema(etree.fromstring(done.stdout.encode("utf-8")))


def tree_xsd(text: str) -> str:
    """The XSD BehaviorTree.CPP generates for the built-ins plus ``text``'s declared nodes."""
    program = find_program()
    if program is None:
        raise CppRuntimeError("BehaviorTree.CPP is not built: run fsmbt doctor --install btcpp")
    root = etree.fromstring(text.encode("utf-8"))
    done = subprocess.run(
        [str(program)],
        input=declarations(root),
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    if done.returncode != 0:
        raise CppRuntimeError(f"fsmbt_btcpp_xsd failed: {done.stderr.strip()[:400]}")
    return done.stdout


def xsd_errors(text: str) -> list[str]:
    """Where ``text`` (a BehaviorTree.CPP file) breaks BehaviorTree.CPP's XSD for it:
    ``line: message`` each, ``[]`` when it validates."""
    program = find_program()
    if program is None:
        raise CppRuntimeError("BehaviorTree.CPP is not built: run fsmbt doctor --install btcpp")
    document = etree.fromstring(text.encode("utf-8"))
    schema = _schema(str(program), declarations(document))
    if schema.validate(document):
        return []
    return [f"{error.line}: {error.message}" for error in schema.error_log]
