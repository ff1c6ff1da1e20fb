"""An FSM run by python-statemachine (a W3C SCXML engine written by others) in a world.

The FSM is written as SCXML by fsmbt's writer and loaded with
``statemachine.io.loader.load(text, format="scxml")`` (its safe evaluator: a guard is evaluated,
never executed as Python). After every event the engine's configuration is read; the action of
the active atomic state (the writer's ``fsmbt:action``, else the state's ``fsmbt:name``, else its
id: an atomic state's action is its name, docs/formats/scxml.md) is what fsmbt's machines would
output. An event the active states take no transition on is ignored, as W3C SCXML says.

- ``SCXMLLeafMachine``: leaf execution (inputs ``success``/``failure``/``running``; a top-level
  ``<final>`` is the root's result, its action ``SUCCESS``/``FAILURE``).
- ``SCXMLEventAgent``: an event-driven role (the predator).
A configuration with more than one active atomic state (a ``<parallel>``) has no single action:
refused with ``UnsupportedError``. If ``statemachine`` does not import, ``available()`` is false
and the caller skips this engine with a note (``fsmbt simulate`` prints it).

Costs: the engine's own (a macro step is O(active states x transitions)); reading the action is
O(active states).
"""

from __future__ import annotations

import contextlib
import io
from typing import Any

from fsmbt.model.errors import UnsupportedError
from fsmbt.model.fsm import FSM

FSMBT_NS = "https://fsmbt.dev/ns/scxml"
ENGINE = "python-statemachine"


def available() -> bool:
    """Whether python-statemachine can be imported here."""
    try:
        import statemachine  # noqa: F401
    except ImportError:
        return False
    return True


class _Chart:
    """The engine's class for one SCXML text, and each state id's action."""

    def __init__(self, text: str) -> None:
        from lxml import etree
        from statemachine.io.loader import load

        root = etree.fromstring(
            text.encode(), etree.XMLParser(resolve_entities=False, no_network=True)
        )
        self.actions: dict[str, str | None] = {}
        for element in root.iter():
            if not isinstance(element.tag, str):
                continue
            local = etree.QName(element).localname
            if local not in ("state", "final") or element.get("id") is None:
                continue
            action = element.get(f"{{{FSMBT_NS}}}action")
            if action is None:
                action = element.get(f"{{{FSMBT_NS}}}name", element.get("id"))
            self.actions[element.get("id", "")] = action or None
        with contextlib.redirect_stdout(io.StringIO()):  # the engine prints <log> content
            self.cls = load(text, format="scxml")


class _Instance:
    def __init__(self, chart: _Chart) -> None:
        self.chart = chart
        with contextlib.redirect_stdout(io.StringIO()):
            self.machine: Any = chart.cls()

    def send(self, event: str) -> None:
        with contextlib.redirect_stdout(io.StringIO()):
            self.machine.send(event)

    def action(self) -> str | None:
        atomic = [s.id for s in self.machine.configuration if not list(s.states)]
        if len(atomic) != 1:
            raise UnsupportedError(
                f"python-statemachine has {len(atomic)} active states "
                f"({', '.join(sorted(atomic))}): a simulation needs one"
            )
        return self.chart.actions.get(atomic[0])

    @property
    def terminated(self) -> bool:
        return bool(self.machine.is_terminated)


def document(model: FSM) -> str:
    """The SCXML text fsmbt's writer makes of ``model``."""
    from fsmbt.formats import dumps

    return dumps(model, "scxml")


#: Charts by SCXML text: python-statemachine reads a document once, every run reuses it.
_CHARTS: dict[str, _Chart] = {}


def _chart(text: str) -> _Chart:
    chart = _CHARTS.get(text)
    if chart is None:
        chart = _CHARTS[text] = _Chart(text)
    return chart


class SCXMLLeafMachine:
    """An FSM on python-statemachine read as a leaf-execution machine (one instance per run)."""

    def __init__(self, text: str, model: FSM | None = None) -> None:
        self.instance = _Instance(_chart(text))

    @staticmethod
    def document(model: FSM) -> str:
        return document(model)

    def _outputs(self) -> tuple[str, ...]:
        action = self.instance.action()
        return (action,) if action is not None else ()

    def start(self) -> tuple[None, tuple[str, ...]]:
        return None, self._outputs()

    def step(self, state: None, symbol: str) -> tuple[None, tuple[str, ...]]:
        self.instance.send(symbol)
        return None, self._outputs()

    def status(self, state: None) -> str:
        return "final" if self.instance.terminated else "running"


class SCXMLEventAgent:
    """An event-driven role played by an FSM on python-statemachine."""

    engine = ENGINE

    def __init__(self, model: FSM) -> None:
        self.text = document(model)
        self.action: str | None = None
        self.instance: _Instance | None = None

    def start(self) -> None:
        self.instance = _Instance(_chart(self.text))
        self.action = self.instance.action()

    def post(self, event: str) -> None:
        assert self.instance is not None, "start() first"
        self.instance.send(event)
        self.action = self.instance.action()

    @property
    def terminated(self) -> bool:
        return self.instance is not None and self.instance.terminated
