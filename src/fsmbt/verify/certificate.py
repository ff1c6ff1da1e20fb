"""Certificates: a verdict that can be re-checked without re-running the search.

Why: a CI or a reviewer should be able to trust a conversion without trusting the checker's
breadth-first search, its state limits or its shortcuts (docs/verification.md, "Certificates").

What a certificate holds (JSON, ``format`` = :data:`FORMAT`):

- the two files' SHA-256 digests by role (source, result), the pairing mode, ``loop`` and
  ``faithful`` (which machines were built: ``fsmbt.verify.pairing.machines_for``), the method,
  engine versions and abstractions of the verdict;
- *equivalent*: both machines' explored tables (per state its description, status and offered
  inputs; per state its edges ``[input, next state, outputs]`` in the order the search met
  them) and the product's relation as pairs of state ids;
- *not equivalent*: each failing property's counterexample (an input sequence).

How it is checked (``check``), in time linear in the certificate (one machine step per edge):

1. the files are the ones certified (digests), read in the same order (``orient``);
2. each machine is rebuilt from its model (fsmbt's interpreter, never the converter) and its
   table is replayed: from the start, every listed edge is one ``step``; a state met for the
   first time gets the next id, which must be the one the certificate names; every state's
   description, status and offered inputs must be the listed ones, and its listed edges must be
   exactly the inputs the machine explores there (its ``active_inputs``, the others being silent
   self-loops by the machine's own contract);
3. the relation must contain the start pair and, for each pair: equal statuses, equal offered
   inputs (unless the result follows the environment), and for every input the source offers,
   equal outputs and a successor pair in the relation.

Step 3 makes the relation a bisimulation between two deterministic machines that contains the
starts, so every input sequence gets the same outputs, statuses and offered inputs from both:
all five properties hold (reachability: the relation is closed under every offered input, so it
covers every reachable state). A not-equivalent certificate is checked by replaying each
counterexample on both machines (``fsmbt.verify.native.replay``): at least one must differ.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
from collections.abc import Hashable, Iterator
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fsmbt import __version__
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.machine import Machine
from fsmbt.verify.method import describe_method
from fsmbt.verify.native import Witness, replay
from fsmbt.verify.pairing import machines_for
from fsmbt.verify.report import Report

FORMAT = "fsmbt-certificate/1"


class CertificateError(InputError):
    """A certificate that does not prove what it claims (refused: exit 1 from the CLI)."""


# -- collecting the witness while ``verify`` runs -------------------------------------------------
@dataclass
class WitnessSink:
    """Where ``fsmbt.verify.verify`` leaves the native check's witness and the flags it used."""

    witness: Witness | None = None
    loop: bool = False
    faithful: bool = False


_SINK: ContextVar[WitnessSink | None] = ContextVar("fsmbt_witness_sink", default=None)


@contextlib.contextmanager
def collecting() -> Iterator[WitnessSink]:
    """Within this block, ``verify`` keeps the native check's witness in the yielded sink (the
    checker's tables stay alive until the sink is dropped: O(|S| + |R| + |P|) memory)."""
    sink = WitnessSink()
    token = _SINK.set(sink)
    try:
        yield sink
    finally:
        _SINK.reset(token)


@contextlib.contextmanager
def collecting_if(wanted: bool) -> Iterator[WitnessSink]:
    """``collecting()`` when a certificate is ``wanted``; else a sink that stays empty and no
    witness is kept (so ``verify`` may choose a method without one, e.g. ``compositional``)."""
    if not wanted:
        yield WitnessSink()
        return
    with collecting() as sink:
        yield sink


def active_sink() -> WitnessSink | None:
    """The sink of the innermost ``collecting`` block, or ``None``."""
    return _SINK.get()


# -- writing --------------------------------------------------------------------------------------
def digest(data: bytes) -> str:
    """The SHA-256 of a file's bytes, as the certificate names files."""
    return hashlib.sha256(data).hexdigest()


def build(
    sink: WitnessSink,
    report: Report,
    *,
    source_digest: str,
    result_digest: str,
) -> dict[str, Any]:
    """The certificate of ``report``, from the witness ``verify`` left in ``sink``.

    Args:
        sink: filled by a ``collecting`` block around the verification.
        report: the verdict (its method, engines and abstractions are copied).
        source_digest, result_digest: ``digest`` of the files in the roles the report gives
            them (after ``orient``: the source is the model the properties call the source).

    Raises:
        InputError: no native witness (the NuSMV engine alone leaves none).
    """
    witness = sink.witness
    if witness is None:
        raise InputError(
            "--certificate needs the native checker's witness: use --verify-engine native or both"
        )
    data: dict[str, Any] = {
        "format": FORMAT,
        "fsmbt": __version__,
        "files": {"source": source_digest, "result": result_digest},
        "mode": report.mode,
        "loop": sink.loop,
        "faithful": sink.faithful,
        "method": report.method,
        "engines": report.engines,
        "abstractions": list(report.abstractions) + list(report.stats.get("abstractions", [])),
        "equivalent": report.equivalent,
    }
    if report.equivalent:
        data.update(witness.to_data())
    else:
        data["counterexamples"] = {
            name: [step.input for step in prop.counterexample[1:]]
            for name, prop in report.properties.items()
            if not prop.holds and prop.counterexample
        }
    return data


def write(data: dict[str, Any], path: Path) -> None:
    """Write a certificate as compact JSON (one line per top-level key is not needed: the
    file is for programs; ``check-certificate`` prints what it proves)."""
    path.write_text(json.dumps(data, separators=(",", ":"), ensure_ascii=False), encoding="utf-8")


# -- checking -------------------------------------------------------------------------------------
@dataclass
class Checked:
    """What a valid certificate proves, for the CLI to print."""

    equivalent: bool
    method: str
    mode: str
    states: dict[str, int] = field(default_factory=dict)
    pairs: int = 0
    steps: int = 0
    abstractions: list[str] = field(default_factory=list)
    engines: dict[str, str] = field(default_factory=dict)


def load(path: Path) -> dict[str, Any]:
    """Read a certificate file; a clear error when it is not one."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise CertificateError(f"cannot read the certificate {path}: {exc}") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise CertificateError(f"{path} is not an fsmbt certificate (format {FORMAT} expected)")
    return data


def check(
    data: dict[str, Any],
    source: FSM | BTDocument,
    result: FSM | BTDocument,
    *,
    source_digest: str,
    result_digest: str,
) -> Checked:
    """Re-validate a certificate for the two models (in the roles the certificate gives them).

    Raises:
        CertificateError: the first thing that does not hold, said in one sentence.
    """
    files = data.get("files") or {}
    if files.get("source") != source_digest or files.get("result") != result_digest:
        raise CertificateError(
            "the certificate was made for other files (their SHA-256 digests differ)"
        )
    loop, faithful = bool(data.get("loop")), bool(data.get("faithful"))
    source_machine, result_machine, mode = machines_for(
        source, result, loop=loop, faithful=faithful
    )
    if mode != data.get("mode"):
        raise CertificateError(
            f"the certificate is for mode {data.get('mode')}, the pair is {mode}"
        )
    method = describe_method(source_machine, result_machine)[0]
    claimed = str(data.get("method", ""))
    if claimed.split("+")[0] != method:
        raise CertificateError(
            f"the certificate claims method {claimed!r}, the machines are checked by {method!r}"
        )
    checked = Checked(
        equivalent=bool(data.get("equivalent")),
        method=str(data.get("method", "")),
        mode=mode,
        abstractions=[str(a) for a in data.get("abstractions", [])],
        engines={str(k): str(v) for k, v in (data.get("engines") or {}).items()},
    )
    try:
        if checked.equivalent:
            _check_equivalent(data, source_machine, result_machine, checked)
        else:
            _check_counterexamples(data, source_machine, result_machine, checked)
    except (KeyError, IndexError, TypeError, ValueError) as exc:
        raise CertificateError(
            f"the certificate is malformed ({type(exc).__name__}: {exc})"
        ) from None
    return checked


def _check_counterexamples(
    data: dict[str, Any], source: Machine[Any], result: Machine[Any], checked: Checked
) -> None:
    traces = data["counterexamples"]
    if not traces:
        raise CertificateError("a not-equivalent certificate without a counterexample")
    for inputs in traces.values():
        run = replay(source, result, [str(symbol) for symbol in inputs])
        checked.steps += len(inputs)
        if run.differs:
            return
    raise CertificateError("no counterexample of the certificate tells the two models apart")


class _Table:
    """One machine's certified table, replayed step by step against the machine itself."""

    def __init__(
        self, role: str, machine: Machine[Any], part: dict[str, Any], outputs: list[tuple[str, ...]]
    ) -> None:
        self.role = role
        self.machine = machine
        self.outputs = outputs
        self.input_sets = [tuple(str(a) for a in key) for key in part["input_sets"]]
        self.frozen = [frozenset(key) for key in self.input_sets]
        self.rows: list[list[Any]] = part["states"]
        self.edges: list[list[list[Any]]] = part["edges"]
        if len(self.rows) != len(self.edges) or not self.rows:
            raise CertificateError(
                f"the {role} table has {len(self.rows)} states and {len(self.edges)} edge lists"
            )
        self.follows = bool(getattr(machine, "follows_environment", False))
        self.offered: list[frozenset[str]] = []
        self.set_ids: list[int] = []
        self.moves: list[dict[str, tuple[int, int]]] = []
        self.status: list[str] = []
        self.steps = 0
        start, start_out = machine.start()
        if self._output_id(tuple(start_out)) != part["start_outputs"]:
            raise CertificateError(f"the {role} machine's start outputs are not the certified ones")
        self._replay(start)

    def _output_id(self, out: tuple[str, ...]) -> int:
        try:
            return self.outputs.index(out)
        except ValueError:
            return -1

    def _replay(self, start: Hashable) -> None:
        machine, role = self.machine, self.role
        active = getattr(machine, "active_inputs", None)
        states: list[Hashable] = [start]
        index: dict[Hashable, int] = {start: 0}
        output_ids = {value: i for i, value in enumerate(self.outputs)}
        seen: dict[int, tuple[object, int]] = {}
        x = 0
        while x < len(states):
            if x >= len(self.rows):
                raise CertificateError(f"the {role} machine reaches more states than certified")
            state = states[x]
            described, status, set_id = self.rows[x]
            given = machine.inputs(state)
            if seen.get(id(given), (None, -1)) != (given, set_id):  # O(inputs) once per set
                if self.input_sets[set_id] != tuple(given):
                    raise CertificateError(
                        f"{role} state {x} offers {list(given)}, not the certified inputs"
                    )
                seen[id(given)] = (given, set_id)
            if machine.status(state) != status:
                raise CertificateError(
                    f"{role} state {x} has status {machine.status(state)!r}, not {status!r}"
                )
            if machine.describe(state) != described:
                raise CertificateError(
                    f"{role} state {x} is {machine.describe(state)!r}, not {described!r}"
                )
            allowed = self.frozen[set_id]
            expected = (
                [a for a in active(state) if a in allowed]
                if active is not None
                else list(self.input_sets[set_id])
            )
            listed = self.edges[x]
            if sorted({str(e[0]) for e in listed}) != sorted(set(expected)) or len(listed) != len(
                set(expected)
            ):
                raise CertificateError(
                    f"{role} state {x}: the certified edges are not the inputs the machine explores"
                )
            row: dict[str, tuple[int, int]] = {}
            for symbol, claimed_next, claimed_out in listed:
                nxt, out = machine.step(state, str(symbol))
                self.steps += 1
                found = index.get(nxt)
                if found is None:
                    found = len(states)
                    index[nxt] = found
                    states.append(nxt)
                out_id = output_ids.get(tuple(out), -1)
                if found != claimed_next or out_id != claimed_out:
                    raise CertificateError(
                        f"{role} state {x} ({described}) on input {symbol!r} goes to state {found} "
                        f"with outputs {list(out)}, not as certified"
                    )
                row[str(symbol)] = (found, out_id)
            self.offered.append(allowed)  # shared per input set: O(1) memory per state
            self.set_ids.append(set_id)
            self.moves.append(row)
            self.status.append(status)
            x += 1
        if len(states) != len(self.rows):
            raise CertificateError(f"the {role} table lists states the machine never reaches")
        self.silent = output_ids.get((), -1)

    def move(self, x: int, symbol: str) -> tuple[int, int]:
        hit = self.moves[x].get(symbol)
        if hit is not None:
            return hit
        return x, self.silent


def _check_equivalent(
    data: dict[str, Any], source: Machine[Any], result: Machine[Any], checked: Checked
) -> None:
    outputs = [tuple(str(o) for o in value) for value in data["outputs"]]
    src = _Table("source", source, data["machines"]["source"], outputs)
    res = _Table("result", result, data["machines"]["result"], outputs)
    relation = {(int(s), int(r)) for s, r in data["relation"]}
    if (0, 0) not in relation:
        raise CertificateError("the relation does not contain the two start states")
    if data["machines"]["source"]["start_outputs"] != data["machines"]["result"]["start_outputs"]:
        raise CertificateError("the two machines' start outputs differ")
    compatible: set[tuple[int, int]] = set()
    for s, r in relation:
        if not (0 <= s < len(src.status) and 0 <= r < len(res.status)):
            raise CertificateError(f"the relation names a state that is not in a table ({s}, {r})")
        if src.status[s] != res.status[r]:
            raise CertificateError(f"related states ({s}, {r}) have different statuses")
        offered_s, offered_r = src.offered[s], res.offered[r]
        key = (src.set_ids[s], res.set_ids[r])
        if key not in compatible:  # O(inputs) once per pair of input sets
            if offered_s != offered_r if not res.follows else not offered_s <= offered_r:
                raise CertificateError(f"related states ({s}, {r}) offer different inputs")
            compatible.add(key)
        # An offered input explored on neither side is a silent self-loop on both: the pair
        # itself is its successor. So only the explored ones need a step.
        s_row, r_row = src.moves[s], res.moves[r]
        for symbol in s_row.keys() | r_row.keys():
            if symbol not in offered_s:
                continue
            s2, o1 = src.move(s, symbol)
            r2, o2 = res.move(r, symbol)
            if o1 != o2:
                raise CertificateError(
                    f"related states ({s}, {r}) give different outputs on {symbol!r}"
                )
            if (s2, r2) not in relation:
                raise CertificateError(
                    f"the relation is not closed: ({s}, {r}) on {symbol!r} leads to ({s2}, {r2})"
                )
    checked.states = {"source": len(src.status), "result": len(res.status)}
    checked.pairs = len(relation)
    checked.steps = src.steps + res.steps
