"""``fsmbt doctor``: fsmbt's optional engines and tools, what each adds, found or not.

fsmbt reads, converts, verifies (its native checker) and writes models with nothing but its
Python dependencies. The rest is optional: NuSMV (a second, independent verifier; path and
version), Graphviz ``dot`` (pictures), behaviortreepy (BehaviorTree.CPP in-process), py_trees,
and the C++ runtime (BehaviorTree.CPP 4.8.2 in the cache and the LEBT driver built from the
current sources or not). Each line says what the tool adds and, when missing, how to get it;
``--install nusmv|btcpp`` builds one into the cache with the build script shipped in the
package (``fsmbt.install``). ``--json`` prints the same as JSON. Paths are printed whole (no
table column cuts them). Exit 0 when all are found, 1 otherwise (``--install``: the build's own
exit status when it fails).
"""

from __future__ import annotations

import importlib
import json
import shutil
import subprocess
from dataclasses import asdict, dataclass
from enum import Enum

import typer


@dataclass
class Check:
    name: str
    ok: bool
    detail: str
    hint: str = ""
    adds: str = ""  # what fsmbt can do with it


class Installable(str, Enum):
    nusmv = "nusmv"
    btcpp = "btcpp"


#: What each optional tool adds (by check name prefix).
ADDS = {
    "NuSMV": "a second, independent verifier (--verify-engine nusmv|both)",
    "Graphviz dot": "SVG/PNG pictures (fsmbt render; DOT text needs nothing)",
    "behaviortreepy": "BehaviorTree.CPP in-process: run converted BTs on the real engine",
    "py_trees": "run converted BTs on py_trees (runtime, simulations)",
    "BehaviorTree.CPP": "the C++ runtime's library (fsmbt runtime cpp, C++ differential checks)",
    "C++ LEBT driver": "run converted BTs through the C++ LEBT runtime",
}


def _nusmv() -> Check:
    from fsmbt.verify.nusmv.binary import ENV_VAR, cached_binary, find_nusmv, nusmv_version

    path = find_nusmv()
    if path is None:
        return Check(
            "NuSMV",
            False,
            f"not found ({ENV_VAR}, PATH, the cache {cached_binary()})",
            f"fsmbt doctor --install nusmv (needs gcc, make, flex, bison) or set {ENV_VAR}",
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
    hint = "fsmbt doctor --install btcpp (needs cmake and g++)"
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
    found = [
        _nusmv(),
        _dot(),
        _module("behaviortreepy", "behaviortreepy", "behaviortreepy"),
        _module("py_trees", "py_trees", "py_trees"),
        *_cpp_runtime(),
    ]
    for check in found:
        check.adds = next((v for k, v in ADDS.items() if check.name.startswith(k)), "")
    return found


def register(app: typer.Typer) -> None:
    @app.command("doctor")
    def doctor_command(
        as_json: bool = typer.Option(False, "--json", help="Print the checks as JSON."),
        install: Installable | None = typer.Option(
            None,
            "--install",
            help="Build an optional engine into the cache (~/.cache/fsmbt): nusmv or btcpp.",
        ),
    ) -> None:
        """Report the optional engines and tools fsmbt uses (NuSMV, Graphviz, behaviortreepy,
        py_trees, the C++ runtime), what each adds and how to get it."""
        if install is not None:
            from fsmbt.install import install as build

            code = build(install.value)
            if code != 0:
                raise typer.Exit(code)
        results = checks()
        if as_json:
            print(json.dumps([asdict(c) for c in results], indent=2))
        else:
            width = max(len(c.name) for c in results)
            for c in results:
                status = "ok     " if c.ok else "missing"
                print(f"{status}  {c.name:<{width}}  {c.detail}")
                print(f"{'':9}{'':<{width}}  adds: {c.adds}")
                if c.hint and not c.ok:
                    print(f"{'':9}{'':<{width}}  get it: {c.hint}")
        if not all(c.ok for c in results):
            raise typer.Exit(1)
