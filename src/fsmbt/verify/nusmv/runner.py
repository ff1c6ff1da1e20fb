"""Running NuSMV on a product model and reading its answer: true/false per SPEC, and each
counterexample as a list of states (full variable valuations; NuSMV prints only changes)."""

from __future__ import annotations

import os
import re
import subprocess
import tempfile
from dataclasses import dataclass, field

from fsmbt.limits import Limits
from fsmbt.verify.nusmv.binary import require_nusmv

DEFAULT_TIMEOUT_S = Limits.nusmv_max_seconds  # the default lives in fsmbt.limits
_SPEC = re.compile(r"^-- (?:specification|invariant) (.*) is (true|false)\s*$")
_STATE = re.compile(r"^\s*-> State: \d+\.\d+ <-")
_INPUT = re.compile(r"^\s*-> Input: \d+\.\d+ <-")
_ASSIGN = re.compile(r"^\s*([\w.\[\]$#-]+) = (\S+)\s*$")


class NuSMVError(RuntimeError):
    """NuSMV failed (syntax/type error in the generated model, crash, timeout): a bug here."""


@dataclass
class TraceState:
    values: dict[str, str]
    inputs: dict[str, str] = field(default_factory=dict)  # the inputs that led here


@dataclass
class SpecResult:
    holds: bool
    trace: list[TraceState] | None = None


def run_nusmv(model: str, expected_specs: int, *, order: str | None = None,
              timeout: float = DEFAULT_TIMEOUT_S, keep: str | None = None) -> tuple[list[SpecResult], float]:
    """Check every SPEC of ``model``; returns the results in file order and NuSMV's seconds."""
    import time

    binary = require_nusmv()
    with tempfile.TemporaryDirectory(prefix="fsmbt-nusmv-") as tmp:
        path = os.path.join(tmp, "product.smv")
        with open(path, "w", encoding="utf-8") as handle:
            handle.write(model)
        if keep:
            with open(keep, "w", encoding="utf-8") as handle:
                handle.write(model)
        # -mono: one monolithic transition relation; the partitioned (IWLS95) default is ~10x
        # slower on these micro-step products.
        command = [str(binary), "-mono"]
        if order:
            order_path = os.path.join(tmp, "product.ord")
            with open(order_path, "w", encoding="utf-8") as handle:
                handle.write(order)
            command += ["-i", order_path]
        started = time.perf_counter()
        try:
            proc = subprocess.run(command + [path], capture_output=True,
                                  text=True, timeout=timeout, cwd=tmp)
        except subprocess.TimeoutExpired:
            raise NuSMVError(f"NuSMV did not finish within {timeout:.0f} s") from None
        elapsed = time.perf_counter() - started
    results = parse_output(proc.stdout)
    if proc.returncode != 0 or len(results) != expected_specs:
        tail = (proc.stderr or proc.stdout).strip().splitlines()[-8:]
        raise NuSMVError(f"NuSMV failed (exit {proc.returncode}, {len(results)} of "
                         f"{expected_specs} specs answered): " + " | ".join(tail))
    return results, elapsed


def parse_output(text: str) -> list[SpecResult]:
    """Spec verdicts and counterexample traces from NuSMV's standard output. NuSMV prints only
    the values that changed, for states and inputs alike: both are carried forward, so every
    ``TraceState`` holds full valuations (inputs: those of the transition into the state)."""
    results: list[SpecResult] = []
    current: list[TraceState] | None = None
    inputs: dict[str, str] = {}
    in_input = False
    for line in text.splitlines():
        match = _SPEC.match(line)
        if match:
            current = None
            results.append(SpecResult(match.group(2) == "true"))
            continue
        if results and not results[-1].holds and line.startswith("Trace Type:"):
            current = []
            results[-1].trace = current
            inputs = {}
            continue
        if current is None:
            continue
        if _STATE.match(line):
            base = dict(current[-1].values) if current else {}
            current.append(TraceState(base, dict(inputs) if current else {}))
            in_input = False
            continue
        if _INPUT.match(line):
            in_input = True
            continue
        if "-- Loop starts here" in line:
            continue
        assign = _ASSIGN.match(line)
        if assign:
            name, value = assign.groups()
            if in_input:
                inputs[name] = value
            elif current:
                current[-1].values[name] = value
    return results
