"""The page in a real browser (Debian's chromium through Playwright) against a real server:
convert the paper's A-J FSM, step a counterexample, download and read back, a malformed file.
Each step writes a screenshot (docs/web.md, 'Screenshots')."""

from __future__ import annotations

from pathlib import Path

from fsmbt import api
from fsmbt.formats import dumps
from fsmbt.generate import random_fsm
from fsmbt.model.errors import InputError
from fsmbt.verify.mutations import mutants
from support.web_server import REPO

PAPER = REPO / "examples" / "paper_fsm.xml"
PAPER_STATES = set("ABCDEFGHIJ")


def _highlighted_texts(page, box: str) -> list[str]:
    """The label text of every highlighted element in one picture."""
    return page.eval_on_selector_all(
        f"#{box} .hl",
        "nodes => nodes.map(n => [...n.querySelectorAll('text')].map(t => t.textContent).join(' '))",
    )


def test_convert_the_paper_fsm_shows_equivalent_and_both_pictures(page, screenshots):
    page.set_input_files("#source-file", str(PAPER))
    page.wait_for_selector("#issues li.ok")
    assert "paper-xml" in page.inner_text("#detected")
    page.screenshot(path=str(screenshots / "01-paper-fsm-loaded.png"))
    page.click("#convert")
    page.wait_for_selector("#convert-results-verdict")
    assert page.inner_text("#convert-results-verdict").startswith("EQUIVALENT")
    # both pictures are SVG drawn from the models: every state of the FSM is an anchor
    for state in "ABCDEFGHIJ":
        assert page.locator(f'#svg-source [id="s@{state}"]').count() == 1
    assert page.locator("#svg-result svg").count() == 1
    assert page.locator('#svg-result [id="n@root"]').count() == 1
    rows = page.locator("#convert-results table.props tbody tr")
    assert rows.count() == 5
    assert page.locator("#convert-results table.props tr.fails").count() == 0
    assert page.locator('[data-metric="graphical"]').count() == 1
    page.screenshot(path=str(screenshots / "02-paper-fsm-converted.png"), full_page=True)


def test_download_the_result_and_read_it_back(page, tmp_path, screenshots):
    page.set_input_files("#source-file", str(PAPER))
    page.wait_for_selector("#issues li.ok")
    page.click("#convert")
    page.wait_for_selector("#convert-results-verdict")
    buttons = page.eval_on_selector_all("button.download", "b => b.map(x => x.dataset.format)")
    assert {"btcpp", "json", "yaml", "dot", "svg", "png"} <= set(buttons)
    with page.expect_download() as info:
        page.click('button.download[data-format="btcpp"]')
    saved = tmp_path / info.value.suggested_filename
    info.value.save_as(saved)
    assert saved.suffix == ".xml"
    loaded = api.load(saved)
    assert loaded.kind == "bt"
    report = api.verify_models(api.load(PAPER).model, loaded.model)
    assert report.equivalent
    with page.expect_download() as info:
        page.click('button.download[data-format="svg"]')
    picture = tmp_path / info.value.suggested_filename
    info.value.save_as(picture)
    assert picture.read_text(encoding="utf-8").startswith("<svg")
    page.screenshot(path=str(screenshots / "03-downloads.png"), full_page=True)


def _mutated_pair(
    tmp_path: Path, style: str = "lebt", machine: Path | None = None
) -> tuple[Path, Path, list]:
    """The paper FSM's (or ``machine``'s) BT in ``style`` (first) and the FSM with one
    transition dropped (second), and the counterexample fsmbt gives for them."""
    source = api.load(machine or PAPER)
    outcome = api.convert_loaded(source, style=style)
    bt_file = api.write_text(outcome.text, tmp_path / "paper_bt.xml")
    for mutant in mutants(source.model, per_operator=1):
        if mutant.operator != "drop_transition":
            continue
        report = api.verify_either_order(outcome.result, mutant.model)
        failed = [p for p in report.properties.values() if not p.holds and p.counterexample]
        if failed:
            trace = min(failed, key=lambda p: len(p.counterexample or [])).counterexample
            fsm_file = api.write(mutant.model, tmp_path / "paper_mutant.scxml")
            assert report.stats["swapped"]  # the FSM is the source of the check
            return bt_file, fsm_file, trace or []
    raise AssertionError("no mutant with a counterexample")


def _verify_on_the_page(page, bt_file: Path, fsm_file: Path) -> None:
    """Upload the pair on the Verify tab, check it, and expect NOT EQUIVALENT."""
    page.click("#tab-verify")
    page.set_input_files("#first-file", str(bt_file))
    page.set_input_files("#second-file", str(fsm_file))
    page.wait_for_function("document.getElementById('second-text').value.length > 0")
    page.click("#verify")
    page.wait_for_selector("#verify-results-verdict")
    assert page.inner_text("#verify-results-verdict").startswith("NOT EQUIVALENT")


def test_verify_a_mutated_pair_and_step_the_counterexample(page, tmp_path, screenshots):
    bt_file, fsm_file, trace = _mutated_pair(tmp_path)
    assert len(trace) >= 3
    _verify_on_the_page(page, bt_file, fsm_file)
    assert page.locator("#verify-results table.props tr.fails").count() >= 1
    assert page.locator("#verify-results table.steps tbody tr").count() == len(trace)
    page.screenshot(path=str(screenshots / "04-counterexample-start.png"), full_page=True)
    for index, step in enumerate(trace):
        if index:
            page.click('#verify-results [data-role="next"]')
        current = page.get_attribute('#verify-results [data-role="stepper"]', "data-current")
        assert current == str(index)
        # the second file (the FSM) is the source of the check, the first (the BT) the result
        fsm_marked = _highlighted_texts(page, "svg-second")
        bt_marked = _highlighted_texts(page, "svg-first")
        if step.source_state in PAPER_STATES:
            assert any(text.strip() == step.source_state for text in fsm_marked), fsm_marked
        else:  # the start: the initial point
            assert page.locator('#svg-second [id="start@"].hl').count() == 1
        if step.result_state in PAPER_STATES:
            assert any(f"state={step.result_state}" in text for text in bt_marked), bt_marked
        else:
            assert page.locator('#svg-first [id="n@root"].hl').count() == 1
        outputs = page.inner_text('#verify-results [data-role="right-out"]')
        assert (
            ", ".join(step.source_outputs) in outputs
            if step.source_outputs
            else "nothing" in outputs
        )
    assert page.is_disabled('#verify-results [data-role="next"]')
    last = trace[-1]
    assert last.note  # the last step is where they differ
    left_out = page.inner_text('#verify-results [data-role="left-out"]')
    assert ", ".join(last.result_outputs) in left_out
    page.screenshot(path=str(screenshots / "05-counterexample-end.png"), full_page=True)


def test_a_step_inside_a_fold_marks_the_folded_node(page, tmp_path):
    """A 40-state machine's dispatch tree (the default style) is drawn with folds; a step
    whose DispatchEntry is folded away marks the folded node above it, never nothing."""
    machine = tmp_path / "big_fsm.json"
    machine.write_text(dumps(random_fsm("fold", 40, start_event=False), "json"), encoding="utf-8")
    bt_file, fsm_file, trace = _mutated_pair(tmp_path, style="dispatch", machine=machine)
    _verify_on_the_page(page, bt_file, fsm_file)
    folds = page.locator("#svg-first text", has_text="nodes]").count()
    assert folds >= 1  # the premise: the tree is folded on the page
    for index in range(len(trace)):
        if index:
            page.click('#verify-results [data-role="next"]')
        assert page.locator("#svg-first .hl").count() >= 1, f"step {index}: nothing marked"


def test_a_malformed_file_shows_its_line_number(page, tmp_path, screenshots):
    lines = PAPER.read_text(encoding="utf-8").splitlines()
    lines[6] = lines[6].replace(">", "", 1) + " <<"
    broken = tmp_path / "broken_fsm.xml"
    broken.write_text("\n".join(lines) + "\n", encoding="utf-8")
    try:
        api.load(broken)
    except InputError as exc:
        expected = exc.location.line if exc.location else None
    else:
        raise AssertionError("the broken file was read")
    assert expected is not None
    page.set_input_files("#source-file", str(broken))
    page.wait_for_selector("#issues li.error")
    assert page.locator(f'#issues a.line[data-line="{expected}"]').count() == 1
    assert f"line {expected}" in page.inner_text("#issues")
    page.click(f'#issues a.line[data-line="{expected}"]')
    page.click("#convert")
    page.wait_for_selector("#convert-error strong")
    assert f"line {expected}" in page.inner_text("#convert-error")
    page.screenshot(path=str(screenshots / "06-malformed-file.png"), full_page=True)


def test_the_page_opens_on_an_example_named_in_the_address(page, server_url):
    page.goto(f"{server_url}/?example=door_hfsm.scxml")
    page.wait_for_selector("body[data-ready='1']")
    page.wait_for_selector("#issues li")
    assert page.input_value("#source-text") == (REPO / "examples" / "door_hfsm.scxml").read_text(
        encoding="utf-8"
    )
    assert page.input_value("#example") == "door_hfsm.scxml"
    # converted on arrival, without a click
    page.wait_for_selector("#convert-results-verdict")
    assert page.inner_text("#convert-results-verdict").startswith("EQUIVALENT")
    assert page.locator('[data-metric="sub_fsms"]').count() == 1
