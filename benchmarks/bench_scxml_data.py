"""SCXML data read exactly (docs/formats/scxml.md, "Data read exactly"): what it costs.

Prints, for the corpus files the data model opens, the states and transitions of the flat
machine (configuration x data values) and the read time; then how long an unbounded counter
takes to reach the state limit (``limits.conversion_max_states``) for a few limits, so the
cost per explored state is visible (it is linear).

    .venv/bin/python benchmarks/bench_scxml_data.py [CORPUS]   (default: $FSMBT_CORPUS or
                                                                 ../shared/corpus)
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

from fsmbt import api, limits
from fsmbt.formats import loads
from fsmbt.formats.scxml.datamodel import StateLimitError

FILES = [
    "w3c_scxml_examples/microwave-01.scxml",
    "w3c_scxml_examples/microwave-02.scxml",
    "commons_scxml/microwave-01-jexl.scxml",
    "scion_tests/internal-transitions__test0.scxml",
    "scion_tests/targetless-transition__test0.scxml",
    "qt_scxml_examples/ftpclient.scxml",
    "scxml_tutorial/virtualSetup.scxml",
]
NS = 'xmlns="http://www.w3.org/2005/07/scxml"'
UNBOUNDED = f"""<scxml {NS} version="1.0" datamodel="ecmascript">
  <datamodel><data id="n" expr="0"/></datamodel>
  <state id="s"><transition event="tick" target="s"><assign location="n" expr="n + 1"/>
    </transition><transition event="stop" cond="n == 3" target="end"/></state>
  <final id="end"/></scxml>"""


def main() -> int:
    default = os.environ.get(
        "FSMBT_CORPUS", str(Path(__file__).resolve().parents[1] / ".." / "shared" / "corpus")
    )
    corpus = Path(sys.argv[1] if len(sys.argv) > 1 else default) / "fsm"
    print("| file | states | transitions | read ms |")
    print("|---|---|---|---|")
    for name in FILES:
        path = corpus / name
        if not path.exists():
            print(f"| {name} | (not found) | | |")
            continue
        start = time.perf_counter()
        model = api.load(path).model
        ms = (time.perf_counter() - start) * 1000
        print(f"| {name} | {len(model.states)} | {len(model.transitions)} | {ms:.0f} |")
    print("\n| conversion_max_states | seconds to the StateLimitError | µs per state |")
    print("|---|---|---|")
    for limit in (5_000, 20_000, 50_000):
        previous = limits.use(limits.current().with_changes(conversion_max_states=limit))
        start = time.perf_counter()
        try:
            loads(UNBOUNDED, "scxml")
            print(f"| {limit} | no error (unexpected) | |")
        except StateLimitError:
            seconds = time.perf_counter() - start
            print(f"| {limit} | {seconds:.2f} | {seconds / limit * 1e6:.0f} |")
        finally:
            limits.use(previous)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
