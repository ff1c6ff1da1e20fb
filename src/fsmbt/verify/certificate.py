"""Certificates: a verdict that can be re-checked without re-running the search.

Why: a CI or a reviewer should be able to trust a conversion without trusting the checker's
breadth-first search, its state limits or its shortcuts (docs/verification.md §6,
"Certificates", which also documents the format).

What a certificate holds (JSON, ``format`` = :data:`FORMAT`):

- the two files' SHA-256 digests by role (source, result), the pairing mode, ``loop`` and
  ``faithful`` (which machines were built: ``fsmbt.verify.pairing.machines_for``), the method,
  engine versions and abstractions of the verdict;
- *equivalent*: a list of ``units``, each a ``kind`` and one local proof: the two machines'
  explored tables (per state its description, status and offered inputs; per state its edges
  ``[input, next state, outputs]`` in the order the search met them) and the relation as pairs
  of state ids. A whole-product proof (methods ``whole product``, ``table``, ``canonical``) is
  one unit of kind ``product``; a compositional proof (docs/semantics.md §4c) is one unit of
  kind ``region`` per paired region (naming the tree region and the region state it pairs)
  and one of kind ``skeleton``, plus the ``decomposition`` it claims (the tree regions' labels
  and the region states' paths). A method that proves by other parts adds its own unit kinds
  and its checker in :data:`METHOD_CHECKS`;
- *not equivalent*: each failing property's counterexample (an input sequence).

How it is checked (``check``), in time linear in the certificate (one machine step per edge):

1. the files are the ones certified (digests), read in the same order (``orient``);
2. each unit's two machines are rebuilt from the models (fsmbt's interpreter, never the
   converter): for a ``product`` unit the pairing's machines; for a compositional proof the
   decomposition is derived again from the models (``compositional.structure``: its side
   conditions checked, its regions compared with the claimed ones), each region's machines and
   the skeleton's are built by the same functions the check used, the skeleton's from the
   pairing the region units name and the results their replayed tables reach; for a region
   proven per node, ``pernode.NodeWalk`` derives which local checks exist and each unit's
   machines are ``pernode.local_machines`` of the nodes it covers (every one covered once);
3. each unit's tables are replayed: from the start, every listed edge is one ``step``; a state
   met for the first time gets the next id, which must be the one the certificate names; every
   state's description, status and offered inputs must be the listed ones, and its listed edges
   must be exactly the inputs the machine explores there (its ``active_inputs``, the others
   being silent self-loops by the machine's own contract);
4. each unit's relation must contain the start pair and, for each pair: equal statuses, equal
   offered inputs (unless the result follows the environment), and for every input the source
   offers, equal outputs and a successor pair in the relation.

Step 4 makes each relation a bisimulation between two deterministic machines that contains the
starts, so every input sequence gets the same outputs, statuses and offered inputs from both:
all five properties hold for that unit's pair (reachability: the relation is closed under every
offered input, so it covers every reachable state); for a compositional proof the units add up
by docs/semantics.md §4c. A not-equivalent certificate is checked by replaying each
counterexample on both machines (``fsmbt.verify.native.replay``): at least one must differ
(for a lifted per-node counterexample, on the machines the lift confirmed it on).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
from collections.abc import Callable, Hashable, Iterator
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fsmbt import __version__
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.dispatch_runtime import is_dispatch_bt
from fsmbt.semantics.execution import Flavour, flavour_of
from fsmbt.semantics.machine import Machine
from fsmbt.verify.compositional import (
    LEAF_EXECUTION,
    PERNODE_UNIT,
    NotDecomposable,
    Parts,
    Structure,
    final_results,
    region_machines,
    results_allowed,
    skeleton_machines,
    structure,
)
from fsmbt.verify.lazy_fsm import Unsupported
from fsmbt.verify.lift import lift_machines, separates
from fsmbt.verify.method import describe_method
from fsmbt.verify.native import Replay, Witness, replay
from fsmbt.verify.pairing import machines_for
from fsmbt.verify.pernode import (
    EVENTS,
    STATUS_OF,
    LocalProblem,
    NodeWalk,
    NotPerNode,
    Sigma,
    local_machines,
)
from fsmbt.verify.report import COMPOSITIONAL, LIFTED, PER_NODE, Report

FORMAT = "fsmbt-certificate/2"
#: The first format: one whole-product proof at the top level (read as one ``product`` unit).
FORMAT_1 = "fsmbt-certificate/1"
#: The unit kinds of the methods this module checks.
PRODUCT, REGION, SKELETON, PERNODE = "product", "region", "skeleton", PERNODE_UNIT


class CertificateError(InputError):
    """A certificate that does not prove what it claims (refused: exit 1 from the CLI)."""


# -- collecting the witness while ``verify`` runs -------------------------------------------------
@dataclass
class WitnessSink:
    """Where ``fsmbt.verify.verify`` leaves the native check's witness and the flags it used."""

    witness: Witness | None = None
    loop: bool = False
    faithful: bool = False
    #: a compositional proof's parts (``None`` when the verdict came from one product)
    parts: Parts | None = None


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
    witness is kept."""
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
    if sink.witness is None and sink.parts is None:
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
    if not report.equivalent:
        data["counterexamples"] = {
            name: [step.input for step in prop.counterexample[1:]]
            for name, prop in report.properties.items()
            if not prop.holds and prop.counterexample
        }
    elif sink.parts is not None:
        parts = sink.parts
        data["decomposition"] = {
            "tree_regions": parts.tree_regions,
            "fsm_regions": parts.fsm_regions,
        }
        units: list[dict[str, Any]] = []
        for part in parts.units:
            unit: dict[str, Any] = {"kind": part.kind}
            if part.kind in (REGION, PERNODE):
                unit["tree_region"], unit["fsm_region"] = part.tree_region, part.fsm_region
            if part.kind == PERNODE:
                unit["nodes"] = list(part.nodes)
                unit["interface"] = {
                    EVENTS[status]: [target, list(assigns)]
                    for status, (target, assigns) in sorted(part.sigma.items())
                }
                unit["halt"] = part.can_halt
            unit.update(part.witness.to_data())
            units.append(unit)
        data["units"] = units
    else:
        assert sink.witness is not None
        data["units"] = [{"kind": PRODUCT, **sink.witness.to_data()}]
    return data


def relation_pairs(data: dict[str, Any]) -> int:
    """How many related state pairs a certificate lists, over all its units."""
    return sum(len(unit.get("relation", ())) for unit in data.get("units", ()))


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
    units: dict[str, int] = field(default_factory=dict)
    steps: int = 0
    abstractions: list[str] = field(default_factory=list)
    engines: dict[str, str] = field(default_factory=dict)


def load(path: Path) -> dict[str, Any]:
    """Read a certificate file; a clear error when it is not one."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise CertificateError(f"cannot read the certificate {path}: {exc}") from None
    if isinstance(data, dict) and data.get("format") == FORMAT_1:
        return upgrade(data)
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise CertificateError(f"{path} is not an fsmbt certificate (format {FORMAT} expected)")
    return data


def upgrade(data: dict[str, Any]) -> dict[str, Any]:
    """A ``fsmbt-certificate/1`` certificate in the current format: its one proof becomes one
    ``product`` unit (nothing else changed, so it is checked as before)."""
    out = {k: v for k, v in data.items() if k not in ("outputs", "machines", "relation")}
    out["format"] = FORMAT
    if "relation" in data:
        out["units"] = [
            {"kind": PRODUCT, **{k: data[k] for k in ("outputs", "machines", "relation")}}
        ]
    return out


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
    claimed = str(data.get("method", ""))
    checked = Checked(
        equivalent=bool(data.get("equivalent")),
        method=claimed,
        mode=str(data.get("mode", "")),
        abstractions=[str(a) for a in data.get("abstractions", [])],
        engines={str(k): str(v) for k, v in (data.get("engines") or {}).items()},
    )
    # a method confirmed by NuSMV too ends in ``+symbolic...``: the native proof is the first
    by_parts = METHOD_CHECKS.get(claimed.split("+")[0])
    try:
        if by_parts is not None and checked.equivalent:
            by_parts(data, source, result, checked)
        elif claimed in LIFTED and not checked.equivalent:
            _check_lifted(data, source, result, checked)
        else:
            _check_whole(data, source, result, checked)
    except (KeyError, IndexError, TypeError, ValueError, AttributeError) as exc:
        raise CertificateError(
            f"the certificate is malformed ({type(exc).__name__}: {exc})"
        ) from None
    return checked


def _check_whole(
    data: dict[str, Any], source: FSM | BTDocument, result: FSM | BTDocument, checked: Checked
) -> None:
    """A proof on the pairing's two machines: one ``product`` unit, or counterexamples."""
    loop, faithful = bool(data.get("loop")), bool(data.get("faithful"))
    source_machine, result_machine, mode = machines_for(
        source, result, loop=loop, faithful=faithful
    )
    if mode != data.get("mode"):
        raise CertificateError(
            f"the certificate is for mode {data.get('mode')}, the pair is {mode}"
        )
    method = describe_method(source_machine, result_machine)[0]
    if checked.method.split("+")[0] != method:
        raise CertificateError(
            f"the certificate claims method {checked.method!r}, the machines are checked by "
            f"{method!r}"
        )
    if not checked.equivalent:
        _check_counterexamples(data, source_machine, result_machine, checked)
        return
    units = data["units"]
    if len(units) != 1 or units[0].get("kind") != PRODUCT:
        raise CertificateError(f"a {method} proof is one unit of kind {PRODUCT!r}")
    src, res, pairs = check_unit(units[0], source_machine, result_machine, "")
    checked.states = {"source": len(src.status), "result": len(res.status)}
    checked.pairs = pairs
    checked.steps = src.steps + res.steps
    checked.units = {PRODUCT: 1}


def _check_lifted(
    data: dict[str, Any], source: FSM | BTDocument, result: FSM | BTDocument, checked: Checked
) -> None:
    """A not-equivalent verdict whose counterexample the per-node check found and
    ``verify/lift.py`` lifted: it must replay, and tell the two models apart, on the machines
    the lift confirmed it on (``lift.lift_machines``: the interpreter's leaf machine and the
    result's data machine expanded lazily, so a large result is not flattened)."""
    if not isinstance(source, BTDocument) or not isinstance(result, FSM):
        raise CertificateError("a lifted counterexample is of a behavior tree against a machine")
    if data.get("mode") != LEAF_EXECUTION or data.get("loop"):
        raise CertificateError(f"a lifted counterexample is in mode {LEAF_EXECUTION}, no loop")
    try:
        source_machine, result_machine = lift_machines(source, result)
    except Unsupported as exc:
        raise CertificateError(f"the result cannot be replayed lazily: {exc}") from None
    # a difference that is not the source refusing its input
    _check_counterexamples(data, source_machine, result_machine, checked, tells_apart=separates)


def _differs(run: Replay) -> bool:
    return run.differs


def _check_counterexamples(
    data: dict[str, Any],
    source: Machine[Any],
    result: Machine[Any],
    checked: Checked,
    *,
    tells_apart: Callable[[Replay], bool] = _differs,
) -> None:
    """Accept when one of the certificate's counterexamples, replayed on the two machines,
    ``tells_apart`` them (cost: one step per listed input)."""
    traces = data["counterexamples"]
    if not traces:
        raise CertificateError("a not-equivalent certificate without a counterexample")
    for inputs in traces.values():
        run = replay(source, result, [str(symbol) for symbol in inputs])
        checked.steps += len(inputs)
        if tells_apart(run):
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
                f"{role} table has {len(self.rows)} states and {len(self.edges)} edge lists"
            )
        self.follows = bool(getattr(machine, "follows_environment", False))
        self.offered: list[frozenset[str]] = []
        self.set_ids: list[int] = []
        self.moves: list[dict[str, tuple[int, int]]] = []
        self.status: list[str] = []
        self.steps = 0
        start, start_out = machine.start()
        self.start_outputs = self._output_id(tuple(start_out))
        if self.start_outputs != part["start_outputs"]:
            raise CertificateError(f"{role} machine's start outputs are not the certified ones")
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
                raise CertificateError(f"{role} machine reaches more states than certified")
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
                frozenset(a for a in active(state) if a in allowed)
                if active is not None
                else allowed
            )
            listed = self.edges[x]
            if len(listed) != len(expected) or {str(e[0]) for e in listed} != expected:
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
            raise CertificateError(f"{role} table lists states the machine never reaches")
        self.silent = output_ids.get((), -1)

    def results(self) -> frozenset[str]:
        """The root results this (tree) table reaches: ``compositional.final_results`` on the
        replayed edges, never on anything the certificate claims about them."""
        return final_results(
            self.status,
            self.outputs[self.start_outputs],
            ((nxt, self.outputs[out]) for row in self.moves for nxt, out in row.values()),
        )

    def move(self, x: int, symbol: str) -> tuple[int, int]:
        hit = self.moves[x].get(symbol)
        if hit is not None:
            return hit
        return x, self.silent


def check_unit(
    unit: dict[str, Any], source: Machine[Any], result: Machine[Any], name: str
) -> tuple[_Table, _Table, int]:
    """Replay one unit's two tables on its rebuilt machines and check its relation (module
    docstring, steps 3 and 4); the replayed tables and the relation's size."""
    where = f"{name}: " if name else ""
    outputs = [tuple(str(o) for o in value) for value in unit["outputs"]]
    src = _Table(f"{where}source", source, unit["machines"]["source"], outputs)
    res = _Table(f"{where}result", result, unit["machines"]["result"], outputs)
    relation = {(int(s), int(r)) for s, r in unit["relation"]}
    if (0, 0) not in relation:
        raise CertificateError(f"{where}the relation does not contain the two start states")
    if unit["machines"]["source"]["start_outputs"] != unit["machines"]["result"]["start_outputs"]:
        raise CertificateError(f"{where}the two machines' start outputs differ")
    compatible: set[tuple[int, int]] = set()
    for s, r in relation:
        if not (0 <= s < len(src.status) and 0 <= r < len(res.status)):
            raise CertificateError(
                f"{where}the relation names a state that is not in a table ({s}, {r})"
            )
        if src.status[s] != res.status[r]:
            raise CertificateError(f"{where}related states ({s}, {r}) have different statuses")
        offered_s, offered_r = src.offered[s], res.offered[r]
        key = (src.set_ids[s], res.set_ids[r])
        if key not in compatible:  # O(inputs) once per pair of input sets
            if offered_s != offered_r if not res.follows else not offered_s <= offered_r:
                raise CertificateError(f"{where}related states ({s}, {r}) offer different inputs")
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
                    f"{where}related states ({s}, {r}) give different outputs on {symbol!r}"
                )
            if (s2, r2) not in relation:
                raise CertificateError(
                    f"{where}the relation is not closed: ({s}, {r}) on {symbol!r} leads to "
                    f"({s2}, {r2})"
                )
    return src, res, len(relation)


# -- a compositional proof (docs/semantics.md §4c), its regions whole or per node (§4d) -------
def _check_compositional(
    data: dict[str, Any], source: FSM | BTDocument, result: FSM | BTDocument, checked: Checked
) -> None:
    """A ``compositional`` proof: ``region`` units and the skeleton (``_check_parts``)."""
    _check_parts(data, source, result, checked, per_node=False)


def _check_pernode(
    data: dict[str, Any], source: FSM | BTDocument, result: FSM | BTDocument, checked: Checked
) -> None:
    """A ``compositional (per node)`` proof: as ``compositional``, with at least one region
    certified by ``pernode`` units (``_check_pernode_region``)."""
    _check_parts(data, source, result, checked, per_node=True)


def _check_parts(
    data: dict[str, Any],
    source: FSM | BTDocument,
    result: FSM | BTDocument,
    checked: Checked,
    *,
    per_node: bool,
) -> None:
    """Re-derive the decomposition from the models, check each region unit on the machines
    ``compositional.region_machines`` builds for the pair it names (or, for a region proven
    per node, its ``pernode`` units: ``_check_pernode_region``), then the skeleton unit on
    the machines ``compositional.skeleton_machines`` builds from those pairs and the results
    the replayed region tables reach. Every side condition of §4c is checked here again:
    structural ones by ``structure``, (2) by ``results_allowed``, (1) and (3) by the units.
    A ``compositional`` proof has no ``pernode`` unit; a ``compositional (per node)`` one has
    at least one."""
    if not isinstance(source, BTDocument) or not isinstance(result, FSM):
        raise CertificateError(
            "a compositional proof is of a behavior tree against a state machine"
        )
    if data.get("loop") or data.get("faithful") or data.get("mode") != LEAF_EXECUTION:
        raise CertificateError(
            f"a compositional proof is in mode {LEAF_EXECUTION}, without loop or faithful machines"
        )
    if is_dispatch_bt(source) or flavour_of(source) is not Flavour.PLAIN:
        raise CertificateError("a compositional proof needs a plain tree (not LEBT or dispatch)")
    try:
        shape = structure(source, result)
    except NotDecomposable as exc:
        raise CertificateError(f"the pair does not decompose: {exc}") from None
    claimed = data["decomposition"]
    if [str(x) for x in claimed["tree_regions"]] != shape.tree_labels():
        raise CertificateError("the tree's regions are not the ones the certificate names")
    if [str(x) for x in claimed["fsm_regions"]] != shape.fsm_paths():
        raise CertificateError("the machine's region states are not the ones the certificate names")
    units = data["units"]
    if not units or units[-1].get("kind") != SKELETON:
        raise CertificateError(f"a compositional proof ends with one {SKELETON!r} unit")
    tree_of_state: dict[int, int] = {}
    results: dict[int, frozenset[str]] = {}
    states = {"source": 0, "result": 0}
    by_region: dict[tuple[int, int], list[dict[str, Any]]] = {}
    order: list[tuple[int, int, dict[str, Any] | None]] = []
    for unit in units[:-1]:
        kind = unit.get("kind")
        if kind not in (REGION, PERNODE) or (kind == PERNODE and not per_node):
            raise CertificateError(
                f"a {checked.method} proof has {REGION!r}"
                + (f" or {PERNODE!r}" if per_node else "")
                + " units, then the skeleton"
            )
        k, j = int(unit["tree_region"]), int(unit["fsm_region"])
        if not (0 <= k < len(shape.regions) and 0 <= j < len(shape.machine_regions)):
            raise CertificateError(f"a region unit names no region ({k}, {j})")
        if kind == PERNODE:
            if (k, j) not in by_region:
                by_region[(k, j)] = []
                order.append((k, j, None))
            by_region[(k, j)].append(unit)
        else:
            order.append((k, j, unit))
    if per_node and not by_region:
        raise CertificateError(f"a {PER_NODE} proof has at least one {PERNODE!r} unit")
    replayed: dict[Any, list[_Replayed]] = {}  # shared by the regions proven per node
    for k, j, unit in order:
        if j in tree_of_state or k in results:
            raise CertificateError(f"a region is paired twice ({k}, {j})")
        name = f"region {shape.regions[k].label} ~ state {shape.machine_regions[j].path}"
        if unit is None:
            possible = _check_pernode_region(
                by_region[(k, j)], shape, k, j, name, checked, states, replayed
            )
        else:
            src, res, pairs = check_unit(unit, *region_machines(shape, k, j), name)
            possible = src.results()
            _count(checked, states, src, res, pairs)
        if not results_allowed(possible, shape, j):
            raise CertificateError(f"{name}: the region ends in {sorted(possible)}")
        tree_of_state[j], results[k] = k, possible
    machines = skeleton_machines(source, result, shape, tree_of_state, results)
    src, res, pairs = check_unit(units[-1], *machines, SKELETON)
    _count(checked, states, src, res, pairs)
    checked.states = states
    regions_whole = sum(1 for _k, _j, unit in order if unit is not None)
    checked.units = {REGION: regions_whole} if regions_whole or not by_region else {}
    if by_region:
        checked.units[PERNODE] = sum(len(found) for found in by_region.values())
    checked.units[SKELETON] = 1


def _check_pernode_region(
    units: list[dict[str, Any]],
    shape: Structure,
    k: int,
    j: int,
    name: str,
    checked: Checked,
    states: dict[str, int],
    replayed: dict[Any, list[_Replayed]],
) -> frozenset[str]:
    """A region proven per node (docs/semantics.md §4d): the local checks are re-derived from
    the two models by ``pernode.NodeWalk`` (the same walk the proof made), each must be
    covered by exactly one unit, and each unit is replayed once (``check_unit``) on the
    ``pernode.local_machines`` of the first node it covers, with the σ and ``halt`` it
    claims; the other nodes it covers must have the same canonical problem (memo key). The
    statuses σ pairs must be exactly those the replayed tree side returns. The region's
    results are its root's interface. ``replayed``: the units already replayed, by canonical
    problem, σ and ``halt`` (``_check_local_unit``). Cost: one grouping of the region, one
    fragment canonicalization per node, one table replay per unit unlike every earlier one."""
    try:
        walk = NodeWalk(shape.regions[k], shape.machine_regions[j].machine, shape.declared)
    except NotPerNode as exc:
        raise CertificateError(f"{name}: not a per-node decomposition ({exc})") from None
    owner: dict[str, int] = {}
    for index, unit in enumerate(units):
        listed = [str(path) for path in unit["nodes"]]
        if not listed:
            raise CertificateError(f"{name}: a {PERNODE!r} unit covers no node")
        for path in listed:
            if path in owner:
                raise CertificateError(f"{name}: node {path!r} is covered twice")
            owner[path] = index
    keys: dict[int, tuple[Any, ...]] = {}
    covered: set[str] = set()
    try:
        for problem in walk.problems():
            path = problem.node.path
            where = f"{name}, node {problem.node.label} at {path or 'the root'}"
            if path not in owner:
                raise CertificateError(f"{where}: no unit covers its local check")
            index = owner[path]
            covered.add(path)
            unit = units[index]
            sigma = _sigma(unit["interface"])
            can_halt = bool(unit["halt"])
            if index not in keys:
                _check_local_unit(unit, problem, sigma, can_halt, where, checked, states, replayed)
                keys[index] = problem.key
            elif keys[index] != problem.key:
                raise CertificateError(f"{where}: not the local problem its unit was checked on")
            walk.settle(problem, sigma, can_halt)
        possible = walk.root_results()
    except NotPerNode as exc:
        raise CertificateError(f"{name}: {exc}") from None
    extra = sorted(set(owner) - covered)
    if extra:
        raise CertificateError(f"{name}: units cover nodes with no local check ({extra[:3]})")
    return possible


def _sigma(data: dict[str, Any]) -> Sigma:
    return {
        STATUS_OF[str(status)]: (int(exit_[0]), tuple(int(a) for a in exit_[1]))
        for status, exit_ in data.items()
    }


@dataclass
class _Replayed:
    """A ``pernode`` unit's proof (outputs, tables, relation) already replayed, and its sizes."""

    proof: tuple[Any, Any, Any]
    source_states: int
    result_states: int
    pairs: int


def _check_local_unit(
    unit: dict[str, Any],
    problem: LocalProblem,
    sigma: Sigma,
    can_halt: bool,
    where: str,
    checked: Checked,
    states: dict[str, int],
    replayed: dict[Any, list[_Replayed]],
) -> None:
    """Replay one ``pernode`` unit on the local machines of ``problem`` with σ and ``halt``.

    A proof equal, item for item, to one already replayed for the same canonical problem, σ
    and ``halt`` is not replayed again: the local machines are a function of those three (the
    memo key's rule, which the coverage of one unit by several nodes already relies on) and
    the replay a function of the machines and the proof, so it would succeed again. Regions
    proven per node repeat local problems (a 10 000-node tree: about half its units)."""
    proof = (unit["outputs"], unit["machines"], unit["relation"])
    earlier = replayed.setdefault((problem.key, tuple(sorted(sigma.items())), can_halt), [])
    for done in earlier:
        if done.proof == proof:
            states["source"] += done.source_states
            states["result"] += done.result_states
            checked.pairs += done.pairs
            return
    tree_side, fragment = local_machines(problem, sigma, can_halt)
    src, res, pairs = check_unit(unit, tree_side, fragment, where)
    if set(sigma) != tree_side.exited:
        raise CertificateError(
            f"{where}: the interface pairs {sorted(EVENTS[s] for s in sigma)}, the node returns "
            f"{sorted(EVENTS[s] for s in tree_side.exited)}"
        )
    _count(checked, states, src, res, pairs)
    earlier.append(_Replayed(proof, len(src.status), len(res.status), pairs))


def _count(checked: Checked, states: dict[str, int], src: _Table, res: _Table, pairs: int) -> None:
    states["source"] += len(src.status)
    states["result"] += len(res.status)
    checked.pairs += pairs
    checked.steps += src.steps + res.steps


#: The methods whose proofs come in parts, each with the function that checks its units (a
#: method proved on one product is checked by ``_check_whole``).
METHOD_CHECKS: dict[
    str, Callable[[dict[str, Any], FSM | BTDocument, FSM | BTDocument, Checked], None]
] = {COMPOSITIONAL: _check_compositional, PER_NODE: _check_pernode}
