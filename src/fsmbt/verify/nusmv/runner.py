"""Running NuSMV on a product model and reading its answer: true/false per SPEC, and each
counterexample as a list of states (full variable valuations; NuSMV prints only changes).

Resource caps (docs/nusmv.md, "Limits"): every run is bounded by ``fsmbt.limits`` -
``nusmv_max_seconds`` (wall time; the child is killed past it, and its CPU time is capped a
little past it as a backstop) and ``nusmv_max_memory_mb`` (the child's address space,
``RLIMIT_AS`` set in the child before ``exec``). The child dies with the process that started
it (Linux ``PR_SET_PDEATHSIG``): no NuSMV outlives a killed run. Going past either
is a ``NuSMVLimitError`` that names the resource, the cap, the model's number of state
variables and how to raise the cap (CLI exit code 4, docs/cli.md). NuSMV's output is decoded as
UTF-8 with ``errors="replace"``: a stray byte never hides the verdicts.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, field

from fsmbt import limits
from fsmbt.child_process import bounded_child
from fsmbt.limits import Limits
from fsmbt.model.errors import FsmbtError, Hint
from fsmbt.verify.nusmv.binary import require_nusmv

DEFAULT_TIMEOUT_S = Limits.nusmv_max_seconds  # the default lives in fsmbt.limits
#: Words NuSMV / CUDD / the C library print when an allocation fails under RLIMIT_AS.
_MEMORY_WORDS = (
    "out of memory",
    "cannot allocate",
    "memory exhausted",
    "bad_alloc",
    "malloc",
    "memory limit",
    "failed to map segment",
)
_VAR_SECTION = re.compile(r"^\s*(?:VAR|IVAR|FROZENVAR)\b(.*)$")
_SECTION = re.compile(
    r"^\s*(?:MODULE|DEFINE|ASSIGN|INIT|TRANS|INVAR|SPEC|CTLSPEC|LTLSPEC|"
    r"INVARSPEC|FAIRNESS|JUSTICE|COMPASSION)\b"
)
_DECLARATION = re.compile(r"^\s*[A-Za-z_][\w.$#\[\]-]*\s*:\s*[^=]")
_SPEC = re.compile(r"^-- (?:specification|invariant) (.*) is (true|false)\s*$")
_STATE = re.compile(r"^\s*-> State: \d+\.\d+ <-")
_INPUT = re.compile(r"^\s*-> Input: \d+\.\d+ <-")
_ASSIGN = re.compile(r"^\s*([\w.\[\]$#-]+) = (\S+)\s*$")


class NuSMVError(RuntimeError):
    """NuSMV failed (syntax/type error in the generated model, crash): a bug here."""


class NuSMVLimitError(FsmbtError):
    """NuSMV went past a resource cap of ``fsmbt.limits`` (memory or time).

    Attributes:
        resource: ``"memory"`` or ``"time"``.
        variables: the number of state and input variables of the model NuSMV was given.
        limit_name: the ``Limits`` field that was exceeded.
    """

    def __init__(self, resource: str, variables: int, limit_name: str, limit: float) -> None:
        unit = "MiB" if resource == "memory" else "s"
        message = (
            f"NuSMV ran out of {resource} at {variables} variables (cap {limit:g} {unit}; "
            f"raise it with {limits.env_name(limit_name)})"
        )
        super().__init__(message, element="NuSMV", hints=(Hint.NUSMV_LIMITS, Hint.NATIVE_VERIFIER))
        self.resource = resource
        self.variables = variables
        self.limit_name = limit_name


def count_variables(model: str) -> int:
    """How many variables (VAR, IVAR, FROZENVAR) an SMV text declares. O(lines)."""
    count = 0
    in_vars = False
    for line in model.splitlines():
        head = _VAR_SECTION.match(line)
        if head:
            in_vars = True
            rest = head.group(1)
            count += bool(_DECLARATION.match(rest))
            continue
        if _SECTION.match(line):
            in_vars = False
            continue
        if in_vars and _DECLARATION.match(line):
            count += 1
    return count


def _out_of_memory(proc: subprocess.CompletedProcess[str]) -> bool:
    text = (proc.stderr + "\n" + proc.stdout[-4000:]).lower()
    # killed by a signal (SIGSEGV/SIGABRT when CUDD's allocation fails), or NuSMV says so
    return proc.returncode < 0 or any(word in text for word in _MEMORY_WORDS)


@dataclass
class TraceState:
    values: dict[str, str]
    inputs: dict[str, str] = field(default_factory=dict)  # the inputs that led here


@dataclass
class SpecResult:
    holds: bool
    trace: list[TraceState] | None = None


def run_nusmv(
    model: str,
    expected_specs: int,
    *,
    order: str | None = None,
    timeout: float | None = None,
    memory_mb: int | None = None,
    keep: str | None = None,
    options: Sequence[str] = (),
    mono: bool = True,
) -> tuple[list[SpecResult], float]:
    """Check every SPEC of ``model``; returns the results in file order and NuSMV's seconds.

    Args:
        model: the SMV text.
        expected_specs: how many verdicts NuSMV must print.
        order: a variable order file's text (``-i``), or ``None``.
        timeout: wall seconds; ``None``: ``limits.current().nusmv_max_seconds``.
        memory_mb: address-space cap of the child, MiB; ``None``:
            ``limits.current().nusmv_max_memory_mb``.
        keep: also write the model to this path (debugging).
        options: more NuSMV command-line options (``-df``, ``-coi``, ``-dynamic``: measured
            by benchmarks/bench_nusmv_options.py; ``check`` passes ``-df`` to its CTL run).
        mono: ``-mono``, one monolithic transition relation (the single-model runs); ``False``:
            NuSMV's default partitioned relation (``check``'s two runs: the monolithic one holds
            the product of both machines' per-input relations, 8.3 against 1.2 CPU s on a
            300-state pair).

    Returns:
        The results in file order and NuSMV's wall seconds.

    Raises:
        NuSMVLimitError: past the time or the memory cap.
        NuSMVError: NuSMV failed otherwise (a bug in the encoding).
    """
    command = [*(["-mono"] if mono else []), *options]
    proc, elapsed = _execute(model, command, order, timeout, memory_mb, keep=keep)
    results = parse_output(proc.stdout)
    if (proc.returncode != 0 or len(results) != expected_specs) and _out_of_memory(proc):
        cap = limits.current().nusmv_max_memory_mb if memory_mb is None else memory_mb
        raise NuSMVLimitError("memory", count_variables(model), "nusmv_max_memory_mb", cap)
    if proc.returncode != 0 or len(results) != expected_specs:
        tail = (proc.stderr or proc.stdout).strip().splitlines()[-8:]
        raise NuSMVError(
            f"NuSMV failed (exit {proc.returncode}, {len(results)} of "
            f"{expected_specs} specs answered): " + " | ".join(tail)
        )
    return results, elapsed


def _execute(
    model: str,
    options: Sequence[str],
    order: str | None,
    timeout: float | None,
    memory_mb: int | None,
    *,
    keep: str | None = None,
    script: str | None = None,
) -> tuple[subprocess.CompletedProcess[str], float]:
    """One NuSMV child on ``model`` under the caps (see ``run_nusmv``): its finished process
    and wall seconds. ``script``: NuSMV commands run by ``-source`` instead of the batch mode
    (the model is still NuSMV's input file; no standard input, so an aborted script ends)."""
    import time

    caps = limits.current()
    timeout = caps.nusmv_max_seconds if timeout is None else timeout
    memory_mb = caps.nusmv_max_memory_mb if memory_mb is None else memory_mb
    binary = require_nusmv()
    with tempfile.TemporaryDirectory(prefix="fsmbt-nusmv-") as tmp:
        path = os.path.join(tmp, "product.smv")
        with open(path, "w", encoding="utf-8") as handle:
            handle.write(model)
        if keep:
            with open(keep, "w", encoding="utf-8") as handle:
                handle.write(model)
        command = [str(binary), *options]
        if order:
            order_path = os.path.join(tmp, "product.ord")
            with open(order_path, "w", encoding="utf-8") as handle:
                handle.write(order)
            command += ["-i", order_path]
        if script is not None:
            script_path = os.path.join(tmp, "commands.txt")
            with open(script_path, "w", encoding="utf-8") as handle:
                handle.write(script)
            command += ["-source", script_path]
        started = time.perf_counter()
        try:
            proc = subprocess.run(
                command + [path],
                capture_output=True,
                stdin=subprocess.DEVNULL,
                text=True,
                encoding="utf-8",
                errors="replace",
                timeout=timeout,
                cwd=tmp,
                preexec_fn=bounded_child(memory_mb, timeout),
            )
        except subprocess.TimeoutExpired:
            raise NuSMVLimitError(
                "time", count_variables(model), "nusmv_max_seconds", timeout
            ) from None
        elapsed = time.perf_counter() - started
    if proc.returncode == -signal.SIGXCPU:  # the CPU backstop of bounded_child
        raise NuSMVLimitError("time", count_variables(model), "nusmv_max_seconds", timeout)
    return proc, elapsed


#: ``check_and_list``'s commands: build the model, one forward search, the invariants on its
#: layers, then every reachable state.
_LIST_SCRIPT = (
    "read_model\nflatten_hierarchy\nencode_variables\nbuild_model\ncompute_reachable\n"
    "{check}print_reachable_states -v\nquit\n"
)
_LISTING = re.compile(r"^#{20,}$", re.MULTILINE)
_STATE_HEAD = re.compile(r"^-+ State\s+\d+ -+$")
_REACHABLE = re.compile(r"^reachable states: (\S+) ")


def list_reachable(
    model: str,
    *,
    order: str | None = None,
    timeout: float | None = None,
    memory_mb: int | None = None,
) -> tuple[list[dict[str, str]], float]:
    """``check_and_list`` of a model without invariants: its reachable states and seconds."""
    _results, states, elapsed = check_and_list(
        model, 0, order=order, timeout=timeout, memory_mb=memory_mb
    )
    return states, elapsed


def check_and_list(
    model: str,
    expected_specs: int,
    *,
    order: str | None = None,
    timeout: float | None = None,
    memory_mb: int | None = None,
) -> tuple[list[SpecResult], list[dict[str, str]], float]:
    """The ``INVARSPEC`` s of ``model`` (verdicts and counterexamples, as ``run_nusmv``; there
    must be ``expected_specs`` of them and no other spec), then every reachable state (its
    state variables' values, as NuSMV prints them), from one build and one forward search
    (``compute_reachable``, ``check_invar`` on its layers, ``print_reachable_states -v``), and
    NuSMV's wall seconds.

    Why: a question about the *set* of reachable states (``fsmbt.verify.nusmv.reach``: which
    states occur in the faithful product, which a machine reaches alone) is one listing,
    where invariants cost one check each over the search's layers (~23 ms per invariant on a
    1 000-state pair's model: 46 s for its 2 000 states, against 2.2 s to list its 6 009
    reachable states; docs/nusmv.md); and the invariants that read the same model share its
    build and search instead of a run of their own. Cost: the forward search plus O(states x
    variables) printed lines, so it is meant for models whose reachable states number in the
    thousands, not millions (the time cap bounds it). The count NuSMV states is checked
    against the list.

    Raises:
        NuSMVLimitError: past the time or the memory cap.
        NuSMVError: NuSMV failed (the script aborted, a verdict is missing, or the list is not
            the stated count).
    """
    script = _LIST_SCRIPT.format(check="check_invar\n" if expected_specs else "")
    options = [] if expected_specs else ["-dcx"]
    proc, elapsed = _execute(model, options, order, timeout, memory_mb, script=script)
    cut = _LISTING.search(proc.stdout)
    head, tail = (proc.stdout[: cut.start()], proc.stdout[cut.start() :]) if cut else ("", "")
    results = parse_output(head)
    states: list[dict[str, str]] = []
    stated: float | None = None
    for line in tail.splitlines():
        if _STATE_HEAD.match(line):
            states.append({})
            continue
        found = _REACHABLE.match(line)
        if found:
            stated = float(found.group(1))
            continue
        assign = _ASSIGN.match(line)
        if assign and states:
            states[-1][assign.group(1)] = assign.group(2)
    if stated is None or stated != len(states) or len(results) != expected_specs:
        if _out_of_memory(proc):
            cap = limits.current().nusmv_max_memory_mb if memory_mb is None else memory_mb
            raise NuSMVLimitError("memory", count_variables(model), "nusmv_max_memory_mb", cap)
        tail_lines = (proc.stderr or proc.stdout).strip().splitlines()[-8:]
        raise NuSMVError(
            f"NuSMV did not check and list ({len(results)} of {expected_specs} specs answered, "
            f"{len(states)} states listed of {stated}; exit {proc.returncode}): "
            + " | ".join(tail_lines)
        )
    return results, states, elapsed


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
