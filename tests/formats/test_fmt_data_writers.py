"""Every FSM writer either keeps a compact conversion's counters as data or names the loss,
located (issue 24 item 3; docs/semantics.md §6a): SCXML, JSON, YAML and SMACH read back with
the same variables and initial values; every other writer - YASMIN among them, whose XML has
no guards - is refused by ``dumps`` and, through ``translate``/``convert``, gets the exact
expansion with a loss naming each variable, its initial value and the first state that reads
and assigns it. SMACH keeps userdata but not a ``<parallel>`` whose regions take turns on it
(a Concurrence runs its children at once): named the same way."""

from __future__ import annotations

import pytest

from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.formats import dumps, loads
from fsmbt.formats.registry import formats, keeps_data
from fsmbt.formats.translate import expand_data_for
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.model.fsm_data import DATAMODEL, has_data, parse_lines

RETRY = (
    '<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M"><Sequence>'
    '<Action ID="X"/><RetryUntilSuccessful num_attempts="3"><Action ID="A"/>'
    "</RetryUntilSuccessful></Sequence></BehaviorTree></root>"
)
PARALLEL = (
    '<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M">'
    '<Parallel name="P" success_count="2" failure_count="2"><Action ID="A"/>'
    '<Sequence><Action ID="B"/><Condition ID="C"/></Sequence><Action ID="D"/></Parallel>'
    "</BehaviorTree></root>"
)
FSM_WRITERS = sorted(f.name for f in formats() if "fsm" in f.kinds and f.write is not None)
#: Writers whose names cannot hold an expansion's flat state names (``X#n=0``): they refuse
#: the expanded machine with a located error instead of writing it.
NAMES_REFUSED = {"pystatemachine"}


def compact(text: str) -> FSM:
    model = bt_to_hfsm(loads(text, "btcpp")).model
    assert isinstance(model, FSM) and has_data(model)
    return model


def test_every_fsm_writer_is_covered() -> None:
    assert {"scxml", "json", "yaml", "smach", "yasmin", "pystatemachine"} <= set(FSM_WRITERS)


@pytest.mark.parametrize("fmt", FSM_WRITERS)
@pytest.mark.parametrize("tree", [RETRY, PARALLEL], ids=["counter", "parallel"])
def test_writer_keeps_the_counters_or_names_the_loss(fmt: str, tree: str) -> None:
    model = compact(tree)
    variables = parse_lines(model.attrs[DATAMODEL])
    names = [name for name, _e in variables]
    if keeps_data(model, fmt):
        assert fmt in {"scxml", "json", "yaml", "smach"}
        text = dumps(model, fmt)
        reader = next(f for f in formats() if f.name == fmt)
        back = loads(text, reader.read_back_as or fmt)
        assert isinstance(back, FSM) and has_data(back)
        assert parse_lines(back.attrs[DATAMODEL]) == variables  # names and initial values
        assert expand_data_for(model, fmt) == (model, None)
        return
    assert fmt not in {"scxml", "json", "yaml"}
    assert fmt != "smach" or tree is PARALLEL
    with pytest.raises(UnsupportedError) as refused:
        dumps(model, fmt)
    expanded, loss = expand_data_for(model, fmt)
    assert loss is not None
    for name, initial in variables:
        assert f"{name} (initial {initial}; read by " in loss, loss
        assert name in str(refused.value)
    assert "first at" in loss and "keep them as data" in loss
    assert isinstance(expanded, FSM) and not has_data(expanded)
    try:
        dumps(expanded, fmt)
    except UnsupportedError as exc:  # a flat name the format cannot hold, named
        assert fmt in NAMES_REFUSED or (fmt == "paper-text" and tree is PARALLEL), exc
        assert "#" in str(exc) and any(n in str(exc) for n in names)
    else:
        assert fmt not in NAMES_REFUSED
