"""``fsmbt doctor``: what fsmbt's optional engines and tools need, found or not.

Checks NuSMV (the second verification engine; path and version), Graphviz ``dot`` (pictures),
behaviortreepy (BehaviorTree.CPP, the differential tests) and py_trees. Exit 0 when all are
found, 1 otherwise; each missing one says how to get it.
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
        return Check("NuSMV", False, "not found",
                     f"run {BUILD_SCRIPT.name} (scripts/) or set {ENV_VAR}")
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
        return Check(label, False, f"cannot import {module}: {type(exc).__name__}",
                     f"pip install {dist} (see pyproject.toml)")
    from importlib.metadata import PackageNotFoundError, version

    try:
        ver = version(dist)
    except PackageNotFoundError:
        ver = "version unknown"
    return Check(label, True, f"{dist} {ver}")


def checks() -> list[Check]:
    return [_nusmv(), _dot(), _module("behaviortreepy", "behaviortreepy", "behaviortreepy"),
            _module("py_trees", "py_trees", "py_trees")]


def register(app: typer.Typer) -> None:
    @app.command("doctor")
    def doctor_command() -> None:
        """Report the external tools fsmbt uses (NuSMV, Graphviz, behaviortreepy, py_trees)."""
        results = checks()
        table = Table("tool", "status", "detail")
        for c in results:
            status = "[green]ok[/green]" if c.ok else "[red]missing[/red]"
            detail = c.detail + (f" - {c.hint}" if c.hint else "")
            table.add_row(c.name, status, detail)
        Console().print(table)
        if not all(c.ok for c in results):
            raise typer.Exit(1)
