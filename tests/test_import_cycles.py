"""No import cycle among the modules of fsmbt and no use of another module's private name
(docs/architecture.md "Checks", issues 10 and 25): ``scripts/import_cycles.py`` lists the cycles,
function-local and ``TYPE_CHECKING`` imports included; ``scripts/private_access.py`` lists
private names imported, reached through a module or on another module's object. Both read the
sources with ``ast`` and run in ``scripts/check.sh``; seeded packages show that each finds what
it looks for."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "scripts" / "import_cycles.py"
PRIVATE = ROOT / "scripts" / "private_access.py"


def run(*args: str, script: Path = SCRIPT) -> tuple[int, str]:
    done = subprocess.run(
        [sys.executable, str(script), *args],
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )
    assert done.stderr == "", done.stderr
    return done.returncode, done.stdout


def cycle_edges(output: str) -> list[str]:
    return [line.strip() for line in output.splitlines() if " -> " in line]


def test_no_import_cycle_in_fsmbt() -> None:
    code, output = run("--root", str(ROOT / "src"))
    assert output.startswith(tuple("0123456789")), output  # the summary line came out
    assert cycle_edges(output) == [], output
    assert code == 0


def test_no_private_name_used_across_modules_of_fsmbt() -> None:
    code, output = run("--root", str(ROOT / "src"), script=PRIVATE)
    assert output.startswith(tuple("0123456789")), output
    assert " 0 use(s)" in output.splitlines()[0], output
    assert code == 0


def test_import_cycles_script_finds_a_local_import_cycle(tmp_path: Path) -> None:
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "a.py").write_text("from pkg.b import thing\n")
    (package / "b.py").write_text(
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from pkg.c import x\n"
        "def thing():\n    from pkg import a\n    return a\n"
    )
    (package / "c.py").write_text("import pkg.b\n")
    code, output = run("--root", str(tmp_path), "--package", "pkg")
    assert code == 1
    assert cycle_edges(output) == [
        "pkg.a -> pkg.b  " + str(package / "a.py") + ":1",
        "pkg.b -> pkg.a  " + str(package / "b.py") + ":5  (local)",
        "pkg.b -> pkg.c  " + str(package / "b.py") + ":3  (typing)",
        "pkg.c -> pkg.b  " + str(package / "c.py") + ":1",
    ]
    code, output = run("--root", str(tmp_path), "--package", "pkg", "--module-level-only")
    assert code == 0 and cycle_edges(output) == []


def test_private_access_script_finds_each_kind_of_use(tmp_path: Path) -> None:
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "_hidden.py").write_text("X = 1\n")
    (package / "a.py").write_text(
        "class Box:\n"
        "    def __init__(self):\n        self._size = 1\n"
        "    def same(self, other):\n        return other._size == self._size\n"
        "def _helper():\n    return 1\n"
        "def peek(box):\n    return box._size\n"
    )
    (package / "b.py").write_text(
        "from typing import TYPE_CHECKING\n"
        "from pkg import a\n"
        "from pkg._hidden import X\n"
        "if TYPE_CHECKING:\n    from pkg.a import _helper\n"
        "def f(box, row):\n"
        "    a._helper()\n"
        "    row._asdict()\n"
        "    return box._size\n"
    )
    code, output = run("--root", str(tmp_path), "--package", "pkg", script=PRIVATE)
    assert code == 1
    found = [line.strip() for line in output.splitlines()[1:]]
    assert found == [
        f"{package / 'a.py'}:9: member: box._size",
        f"{package / 'b.py'}:3: import: from pkg._hidden import X",
        f"{package / 'b.py'}:5: import: from pkg.a import _helper",
        f"{package / 'b.py'}:7: module: a._helper (pkg.a)",
        f"{package / 'b.py'}:9: member: box._size",
    ]
