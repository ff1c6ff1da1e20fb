"""``fsmbt doctor``: what fsmbt's optional engines and tools need, found or not.

Checks NuSMV (the second verification engine; path and version), Graphviz ``dot`` (pictures),
behaviortreepy (BehaviorTree.CPP, the differential tests), py_trees, and the C++ runtime built
by ``scripts/build_btcpp.sh`` (BehaviorTree.CPP's install prefix in the cache, the LEBT driver
built from the current sources or not). Exit 0 when all are found, 1 otherwise; each missing one
says how to get it.
"""

from __future__ import annotations

import importlib
import shutil
import subprocess
from dataclasses import dataclass

import typer
from rich.console import Console
from rich.table import Table


@dataclass
class Check:
    name: str
    ok: bool
    detail: str
    hint: str = ""


def _nusmv() -> Check:
    from fsmbt.verify.nusmv.binary import BUILD_SCRIPT, ENV_VAR, find_nusmv, nusmv_version

    path = find_nusmv()
    if path is None:
        return Check(
            "NuSMV", False, "not found", f"run {BUILD_SCRIPT.name} (scripts/) or set {ENV_VAR}"
        )
    return Check("NuSMV", True, f"{nusmv_version(str(path))} at {path}")


def _dot() -> Check:
    path = shutil.which("dot")
    if path is None:
        return Check("Graphviz dot", False, "not found", "apt-get install graphviz")
    try:
        proc = subprocess.run([path, "-V"], capture_output=True, text=True, timeout=20)
        version = (proc.stderr or proc.stdout).strip().splitlines()[0]
    except (OSError, subprocess.TimeoutExpired, IndexError):
        version = "version unknown"
    return Check("Graphviz dot", True, f"{version} at {path}")


def _module(label: str, module: str, dist: str) -> Check:
    try:
        importlib.import_module(module)
    except Exception as exc:  # noqa: BLE001 - a broken install is reported, not raised
        return Check(
            label,
            False,
            f"cannot import {module}: {type(exc).__name__}",
            f"pip install {dist} (see pyproject.toml)",
        )
    from importlib.metadata import PackageNotFoundError, version

    try:
        ver = version(dist)
    except PackageNotFoundError:
        ver = "version unknown"
    return Check(label, True, f"{dist} {ver}")


def _cpp_runtime() -> list[Check]:
    from fsmbt.runtime.cpp import BTCPP_VERSION, library_prefix, status

    found = status()
    hint = "run scripts/build_btcpp.sh (needs cmake and g++)"
    library = (
        Check(f"BehaviorTree.CPP {BTCPP_VERSION} (C++)", True, f"built at {found.library}")
        if found.library
        else Check(
            f"BehaviorTree.CPP {BTCPP_VERSION} (C++)",
            False,
            f"not built at {library_prefix()}",
            hint,
        )
    )
    driver = (
        Check("C++ LEBT driver", True, f"built at {found.driver}")
        if found.driver
        else Check("C++ LEBT driver", False, found.problem, hint)
    )
    return [library, driver]


def checks() -> list[Check]:
    return [
        _nusmv(),
        _dot(),
        _module("behaviortreepy", "behaviortreepy", "behaviortreepy"),
        _module("py_trees", "py_trees", "py_trees"),
        *_cpp_runtime(),
    ]


def register(app: typer.Typer) -> None:
    @app.command("doctor")
    def doctor_command() -> None:
        """Report the external tools fsmbt uses (NuSMV, Graphviz, behaviortreepy, py_trees, the
        C++ runtime)."""
        results = checks()
        table = Table("tool", "status", "detail")
        for c in results:
            status = "[green]ok[/green]" if c.ok else "[red]missing[/red]"
            detail = c.detail + (f" - {c.hint}" if c.hint else "")
            table.add_row(c.name, status, detail)
        Console().print(table)
        if not all(c.ok for c in results):
            raise typer.Exit(1)
