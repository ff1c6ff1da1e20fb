"""The native checker's wall-time limit (``fsmbt.limits``: ``checker_max_seconds``): past it the
check stops with ``CheckerTimeLimitError`` (undecided, never a verdict), from the library, from
the limits in force and through the CLI (exit 4, one line naming ``--timeout``)."""

from __future__ import annotations

import copy

import pytest

from fsmbt import api, limits
from fsmbt.cli import EXIT_LIMIT, main
from fsmbt.generate.generator import random_fsm
from fsmbt.verify.native import CheckerTimeLimitError, StateLimitError, check
from fsmbt.verify.pairing import machines_for

#: Comfortably more states than the deadline's check interval (1 024), so the clock is read.
STATES = 5_000


@pytest.fixture(scope="module")
def big_fsm():
    return random_fsm(seed=7, n_states=STATES, shape="chain")


@pytest.fixture()
def restore_limits():
    saved = limits.current()
    yield
    limits.use(saved)


def test_a_tiny_time_limit_stops_the_check_undecided(big_fsm):
    source, result, _mode = machines_for(big_fsm, copy.deepcopy(big_fsm))
    with pytest.raises(CheckerTimeLimitError) as caught:
        check(source, result, max_seconds=1e-9)
    assert isinstance(caught.value, StateLimitError)  # the batch runner's "over a limit" class
    assert "stopped after" in str(caught.value) and "undecided" in str(caught.value)


def test_the_same_check_within_its_limit_decides(big_fsm):
    source, result, _mode = machines_for(big_fsm, copy.deepcopy(big_fsm))
    report = check(source, result, max_seconds=600)
    assert report.equivalent
    assert report.stats["source_states"] >= STATES


def test_the_limit_in_force_applies_when_none_is_given(big_fsm, restore_limits):
    limits.use(limits.current().with_changes(checker_max_seconds=1e-9))
    source, result, _mode = machines_for(big_fsm, copy.deepcopy(big_fsm))
    with pytest.raises(CheckerTimeLimitError):
        check(source, result)


def test_cli_timeout_exits_4_naming_the_flag(big_fsm, tmp_path, capsys, restore_limits):
    a = api.write(big_fsm, tmp_path / "a.json")
    b = api.write(copy.deepcopy(big_fsm), tmp_path / "b.json")
    code = main(["verify", str(a), str(b), "--timeout", "0.001"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == EXIT_LIMIT
    assert len(err) == 1 and "native checker stopped" in err[0] and "--timeout" in err[0]
