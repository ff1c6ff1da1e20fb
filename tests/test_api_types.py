"""The typed requests of the API boundary (fsmbt.api_types): one definition, validated."""

from pathlib import Path

import pytest
from pydantic import ValidationError

from fsmbt import api, limits
from fsmbt.api_types import ConvertRequest, ReadOptions, convert_request, verify_request
from fsmbt.model.errors import InputError

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_flat_options_split_into_reader_and_engine_options() -> None:
    request = convert_request(
        source_format="btcpp",
        options={"nodes": "nav2,moveit_pro", "abstract": ["time"], "llm_model": "m"},
    )
    assert request.read.format == "btcpp"
    assert request.read.nodes == ["nav2", "moveit_pro"]
    assert request.read.reader_options() == {"nodes": ["nav2", "moveit_pro"], "abstract": ["time"]}
    assert request.engine_options == {"llm_model": "m"}


def test_unknown_or_mistyped_options_are_named() -> None:
    with pytest.raises(InputError, match="verifyengine"):
        convert_request(verifyengine="nusmv")
    with pytest.raises(InputError, match="verify_engine"):
        convert_request(verify_engine="z3")
    with pytest.raises(InputError, match="hierarchy"):
        convert_request(hierarchy="nested")
    with pytest.raises(InputError, match="max_states"):
        verify_request(max_states=0)


def test_requests_are_values() -> None:
    request = ConvertRequest(engine="bsd")
    changed = convert_request(request, loop=True)
    assert (request.loop, changed.loop, changed.engine) == (False, True, "bsd")
    with pytest.raises(ValidationError, match="frozen"):
        request.loop = True  # type: ignore[misc]


def test_unset_state_limit_is_the_limits_in_force() -> None:
    with limits.changed(checker_max_states=1234):
        assert ConvertRequest().checker_limit() == 1234
        assert verify_request().checker_limit() == 1234
    assert ConvertRequest(max_states=7).checker_limit() == 7


def test_one_request_drives_the_pipeline(tmp_path: Path) -> None:
    request = ConvertRequest(engine="rules", to="json", read=ReadOptions(format="paper-xml"))
    outcome = api.convert_file(EXAMPLES / "paper_fsm.xml", tmp_path / "bt.json", request)
    assert outcome.written and outcome.output_format == "json" and outcome.equivalent
    # the keyword spelling builds the same request over the given one
    again = api.convert_file(EXAMPLES / "paper_fsm.xml", None, request, verify=False)
    assert again.report is None and again.text == outcome.text
