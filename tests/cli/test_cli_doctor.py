"""``fsmbt doctor`` (docs/cli.md; issue 25): every optional tool says what it adds, a missing one
how to get it (``fsmbt doctor --install ...``), paths whole, ``--json``; ``--install`` runs the
build script shipped in the package and passes its failure on."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import fsmbt.install
from fsmbt.cache import BTCPP_BUILD
from fsmbt.cli import main


def test_doctor_json_names_what_each_tool_adds_and_how_to_get_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setenv("FSMBT_CACHE", str(tmp_path / "empty-cache"))  # no C++ build, no NuSMV
    monkeypatch.setenv("FSMBT_NUSMV", str(tmp_path / "no-NuSMV"))
    monkeypatch.setenv("PATH", "/usr/bin:/bin")
    assert main(["doctor", "--json"]) == 1
    checks = {c["name"]: c for c in json.loads(capsys.readouterr().out)}
    assert all(c["adds"] for c in checks.values())
    assert not checks["NuSMV"]["ok"] and "fsmbt doctor --install nusmv" in checks["NuSMV"]["hint"]
    driver = checks["C++ LEBT driver"]
    assert not driver["ok"] and "fsmbt doctor --install btcpp" in driver["hint"]
    # the plain form prints the cache path whole, however long
    assert main(["doctor"]) == 1
    out = capsys.readouterr().out
    assert str(tmp_path / "empty-cache" / f"btcpp-{BTCPP_BUILD}") in out


def test_the_build_scripts_ship_in_the_package() -> None:
    for engine in ("nusmv", "btcpp"):
        script = fsmbt.install.build_script(engine)
        assert script.is_file() and script.parent == Path(fsmbt.install.__file__).parent
        assert script.read_text(encoding="utf-8").startswith("#!/usr/bin/env bash")


def test_doctor_install_runs_the_packaged_script_and_passes_its_failure_on(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    fake = tmp_path / "build_fake.sh"
    seen = tmp_path / "python.txt"
    fake.write_text(f'printf "%s" "$PYTHON" > "{seen}"\nexit 3\n', encoding="utf-8")
    monkeypatch.setitem(fsmbt.install.SCRIPTS, "nusmv", fake)
    monkeypatch.delenv("PYTHON", raising=False)
    assert main(["doctor", "--install", "nusmv"]) == 3
    assert Path(seen.read_text(encoding="utf-8")).name.startswith("python")
    assert main(["doctor", "--install", "gcc"]) == 2  # not an engine fsmbt builds
    assert "gcc" in capsys.readouterr().err
