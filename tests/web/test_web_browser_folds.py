"""Folds opened on the page in a real browser (Debian's chromium through Playwright, against a
real ``fsmbt serve``; issue 29, item 6; docs/web.md 'Big models'): a hierarchical FSM too big
for one layered picture shows its composite states closed, its conversion a folded tree; a
click on a closed composite draws its states, a click on a ``[k nodes]`` box draws the
subtree's nodes, and the breadcrumb goes back to the whole picture."""

from __future__ import annotations

from support.web_models import hierarchical_scxml


def _ids(page, box: str, prefix: str) -> set[str]:
    return set(
        page.eval_on_selector_all(f"#{box} g[id^='{prefix}']", "nodes => nodes.map(n => n.id)")
    )


def _convert_the_hierarchical_fsm(page) -> None:
    page.fill("#source-text", hierarchical_scxml(groups=8, inner=10))
    page.wait_for_selector("#issues li")
    page.click("#convert")
    page.wait_for_selector("#convert-results-verdict")
    assert page.inner_text("#convert-results-verdict").startswith("EQUIVALENT")


def test_clicking_a_closed_composite_state_draws_its_states_and_the_crumb_goes_back(
    page, screenshots
):
    _convert_the_hierarchical_fsm(page)
    closed = page.locator("#svg-source g.fold")
    assert closed.count() == 8  # the premise: every composite is closed
    assert "s@G3/G3_0" not in _ids(page, "svg-source", "s@")
    page.locator('#svg-source g.fold[id="s@G3"]').click()
    page.wait_for_selector('#svg-source[data-level="1"]')
    assert _ids(page, "svg-source", "s@") == {f"s@G3/G3_{i}" for i in range(10)}
    crumbs = page.inner_text('#convert-results [data-role="left-crumbs"]')
    assert "whole model" in crumbs and "G3" in crumbs
    page.screenshot(path=str(screenshots / "07-composite-opened.png"), full_page=True)
    page.click('#convert-results [data-role="left-crumbs"] a.crumb[data-level="0"]')
    page.wait_for_selector('#svg-source[data-level="0"]')
    assert page.locator("#svg-source g.fold").count() == 8


def test_clicking_a_fold_box_draws_the_subtree_nodes(page, screenshots):
    _convert_the_hierarchical_fsm(page)
    folds = sorted(_ids(page, "svg-result", "fold@"))
    assert folds  # the premise: the converted tree is folded
    before = _ids(page, "svg-result", "n@")
    target = folds[0]
    path = target.removeprefix("fold@")
    page.locator(f'#svg-result g.fold[id="{target}"]').click()
    page.wait_for_selector('#svg-result[data-level="1"]')
    after = _ids(page, "svg-result", "n@")
    assert f"n@{path}" in after
    # every node drawn is in the opened subtree, and the fold's hidden nodes now appear
    assert all(n == f"n@{path}" or n.startswith(f"n@{path}/") for n in after)
    hidden = {n for n in after if n.startswith(f"n@{path}/")}
    assert hidden and not (hidden & before)
    label = page.inner_text('#convert-results [data-role="right-crumbs"] .crumb.current')
    assert label == path
    page.screenshot(path=str(screenshots / "08-fold-opened.png"), full_page=True)
    page.click('#convert-results [data-role="right-crumbs"] a.crumb[data-level="0"]')
    page.wait_for_selector('#svg-result[data-level="0"]')
    assert _ids(page, "svg-result", "n@") == before
