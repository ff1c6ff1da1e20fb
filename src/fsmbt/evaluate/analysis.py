"""The report's tables, computed from the stored rows, the manifest and the result files.

Every number here is measured on this run: accuracy = verified-equivalent results / results
produced (refused and unreadable inputs are counted apart, never as successes), with Wilson
95 % intervals (``stats.wilson``); elements are counted on the result files read back
(``fsmbt.metrics.elements``); a method that did not run is the text ``NOT_RUN``.
Cost: O(rows), plus reading every result file once.
"""

from __future__ import annotations

import statistics
from collections import defaultdict
from pathlib import Path
from typing import Any, cast

from fsmbt import api
from fsmbt.evaluate.dataset import Entry
from fsmbt.evaluate.paper import PAPER_FORMULAS, PAPER_SLOPES
from fsmbt.evaluate.plan import NOT_RUN, RULE_ENGINES, STRUCTURED, Planned
from fsmbt.evaluate.stats import fit_slope, wilson
from fsmbt.metrics import elements
from fsmbt.metrics.formulas import bsd, chds, hfsm, lebt
from fsmbt.verify import PROPERTIES

GROUPS = ("basic", "robot", "game", "example", "corpus")
#: Measured elements must lie within this relative band of our exact formulas (the test checks).
FORMULA_BAND = 0.25


def rows(planned: list[Planned], results: list[Any], entries: list[Entry]) -> list[dict[str, Any]]:
    """One flat row per stored result, joined with its job and its model's manifest entry."""
    by_key = {p.job.key: p for p in planned}
    by_id = {e.id: e for e in entries}
    joined = []
    for result in results:
        p = by_key.get(result.key)
        if p is None:
            continue
        entry = by_id[p.entry_id]
        joined.append(
            {
                "key": result.key,
                "model": entry.id,
                "scenario": entry.scenario,
                "group": entry.scenario if entry.source == "generated" else entry.source,
                "kind": entry.kind,
                "source": entry.source,
                "method": p.method,
                "verifier": p.verifier,
                "status": result.status,
                "verdict": result.verdict,
                "properties": dict(result.properties or {}),
                "error_class": result.error_class,
                "error_message": result.error_message,
                "timings": dict(result.timings or {}),
                "output": result.output,
                "stats": dict(result.stats or {}),
                "size": dict(entry.size),
            }
        )
    return joined


def accuracy(table_rows: list[dict[str, Any]], methods: list[str]) -> list[dict[str, Any]]:
    """Per method and group: produced, equivalent, share with its Wilson interval, refused."""
    out = []
    for method in methods:
        for group in (*GROUPS, "all"):
            chosen = [
                r
                for r in table_rows
                if r["method"] == method
                and r["verifier"] == "native"
                and (group == "all" or r["group"] == group)
            ]
            if method not in (*RULE_ENGINES, STRUCTURED) and not chosen:
                out.append({"method": method, "group": group, "text": NOT_RUN})
                continue
            produced = [r for r in chosen if r["status"] in ("equivalent", "not_equivalent")]
            good = sum(r["status"] == "equivalent" for r in produced)
            low, high = wilson(good, len(produced))
            row: dict[str, Any] = {
                "method": method,
                "group": group,
                "attempted": len(chosen),
                "produced": len(produced),
                "equivalent": good,
                "accuracy": good / len(produced) if produced else None,
                "wilson_low": low,
                "wilson_high": high,
                "refused": sum(r["status"] == "refused" for r in chosen),
                "bad_input": sum(r["status"] == "bad_input" for r in chosen),
                "error": sum(r["status"] in ("error", "limit", "timeout") for r in chosen),
            }
            out.append(row)
    return out


def consistency(
    table_rows: list[dict[str, Any]], methods: list[str], models: tuple[str, ...]
) -> list[dict[str, Any]]:
    """The five properties per method on the named models (Tables III and VIII)."""
    out = []
    for model in models:
        for method in methods:
            found = [
                r
                for r in table_rows
                if r["model"] == model and r["method"] == method and r["verifier"] == "native"
            ]
            if not found:
                out.append({"model": model, "method": method, "text": NOT_RUN})
                continue
            row = found[0]
            out.append(
                {
                    "model": model,
                    "method": method,
                    "status": row["status"],
                    **{name: row["properties"].get(name) for name in PROPERTIES},
                }
            )
    return out


def _paper_method(method: str) -> str:
    """The paper's method a method is measured beside: the structured style beside the LEBT
    formula (the paper has none for it)."""
    return "rules" if method == STRUCTURED else method


def _prediction(direction: str, method: str, m: int, k: int, t: int) -> int:
    method = _paper_method(method)
    if direction == "fsm->bt":
        return {"rules": lebt(m), "bsd": bsd(m), "chds": chds(m, t)}[method]
    return hfsm(m, k) if method != "bsd" else hfsm(m, 0)


def element_rows(table_rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Graphical and active elements of every produced rule-engine result, with M and k."""
    out = []
    for r in table_rows:
        if r["method"] not in (*RULE_ENGINES, STRUCTURED) or r["verifier"] != "native":
            continue
        if not r["output"]:
            continue
        if r["status"] not in ("equivalent", "not_equivalent") or not Path(r["output"]).exists():
            continue
        result = elements(api.load(r["output"], "json").model)
        conversion = r["stats"].get("conversion", {})
        if r["kind"] == "fsm":
            direction = "fsm->bt"
            m = int(conversion.get("states", r["size"].get("states", 0)))
            t = int(conversion.get("switches", conversion.get("transitions", 0)))
        else:
            direction = "bt->fsm"
            m = int(r["size"].get("leaves", 0))
            t = 0
        k = result.sub_fsms
        out.append(
            {
                "model": r["model"],
                "group": r["group"],
                "method": r["method"],
                "direction": direction,
                "M": m,
                "k": k,
                "graphical": result.graphical,
                "active": result.active,
                "ours": _prediction(direction, r["method"], m, k, t),
                "seconds": r["timings"].get("convert", 0.0),
                "source_graphical": r["size"].get("graphical", 0),
            }
        )
    return out


def formula_table(measured: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per direction and method: the fitted slope of graphical elements in M (with its
    standard error) next to the paper's coefficient, and the deviation from our formula."""
    groups: dict[tuple[str, str], list[dict[str, Any]]] = defaultdict(list)
    for row in measured:
        groups[(row["direction"], row["method"])].append(row)
    out = []
    for (direction, method), chosen in sorted(groups.items()):
        x = [float(r["M"]) for r in chosen]
        slope, error, intercept = fit_slope(x, [float(r["graphical"]) for r in chosen])
        active_slope, active_error, _ = fit_slope(x, [float(r["active"]) for r in chosen])
        deviations = [(r["graphical"] - r["ours"]) / r["ours"] for r in chosen if r["ours"]]
        out.append(
            {
                "direction": direction,
                "method": method,
                "n": len(chosen),
                "paper_formula": PAPER_FORMULAS[(direction, _paper_method(method))]
                + (" (LEBT, beside)" if method == STRUCTURED else ""),
                "paper_slope": PAPER_SLOPES[(direction, _paper_method(method))],
                "fitted_slope": slope,
                "slope_error": error,
                "intercept": intercept,
                "active_slope": active_slope,
                "active_slope_error": active_error,
                "mean_deviation_from_ours": statistics.fmean(deviations) if deviations else None,
                "max_abs_deviation_from_ours": max(abs(d) for d in deviations)
                if deviations
                else None,
                "within_band": (sum(abs(d) <= FORMULA_BAND for d in deviations) / len(deviations))
                if deviations
                else None,
            }
        )
    return out


def cost(table_rows: list[dict[str, Any]], methods: list[str]) -> list[dict[str, Any]]:
    """Seconds per conversion and per verification, per method (tokens: LLM only)."""
    out = []
    for method in methods:
        chosen = [
            r
            for r in table_rows
            if r["method"] == method
            and r["verifier"] == "native"
            and r["status"] in ("equivalent", "not_equivalent")
        ]
        if not chosen:
            text = "no model of its kind" if method == STRUCTURED else NOT_RUN
            out.append({"method": method, "text": text})
            continue
        convert = sorted(r["timings"].get("convert", 0.0) for r in chosen)
        verify = sorted(r["timings"].get("verify", 0.0) for r in chosen)
        out.append(
            cast(
                dict[str, Any],
                {
                    "method": method,
                    "n": len(chosen),
                    "convert_median_s": statistics.median(convert),
                    "convert_p95_s": convert[int(0.95 * (len(convert) - 1))],
                    "convert_max_s": convert[-1],
                    "verify_median_s": statistics.median(verify),
                    "verify_p95_s": verify[int(0.95 * (len(verify) - 1))],
                    "tokens": NOT_RUN,
                },
            )
        )
    return out


def nusmv_table(table_rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The NuSMV sample: per method, rows checked by native and NuSMV together."""
    out = []
    for method in RULE_ENGINES:
        chosen = [r for r in table_rows if r["method"] == method and r["verifier"] == "both"]
        out.append(
            {
                "method": method,
                "sampled": len(chosen),
                "both_equivalent": sum(r["status"] == "equivalent" for r in chosen),
                "not_equivalent": sum(r["status"] == "not_equivalent" for r in chosen),
                "not_encodable_or_error": sum(
                    r["status"] not in ("equivalent", "not_equivalent") for r in chosen
                ),
                "reasons": sorted(
                    {(r["error_message"] or "")[:90] for r in chosen if r["error_message"]}
                )[:3],
            }
        )
    return out


def nusmv_sample_rows(
    table_rows: list[dict[str, Any]], entries: list[Entry]
) -> list[dict[str, Any]]:
    """Which models NuSMV checked, each with its size and the verdict per method."""
    by_id = {e.id: e for e in entries}
    found: dict[str, dict[str, Any]] = {}
    for r in table_rows:
        if r["verifier"] != "both" or r["method"] not in RULE_ENGINES:
            continue
        entry = by_id[r["model"]]
        row = found.setdefault(
            entry.id,
            {
                "model": entry.id,
                "source": entry.source,
                "kind": entry.kind,
                "size": (
                    f"{entry.size.get('states', 0)} states"
                    if entry.kind == "fsm"
                    else f"{entry.size.get('nodes', 0)} nodes"
                ),
            },
        )
        # a NuSMV encoder refusal is stored as bad_input (the reasons column names it)
        row[r["method"]] = "not encodable" if r["status"] == "bad_input" else r["status"]
        row[f"{r['method']}_seconds"] = r["timings"].get("verify")
    return sorted(found.values(), key=lambda row: (row["source"] != "example", row["model"]))


def _edit_cell(row: dict[str, Any]) -> str:
    if row["distance"] is None:
        return "error"
    return f"{'' if row['exact'] else '≤'}{row['distance']:.0f}"


def headline(
    key: tuple[str, ...],
    acc: list[dict[str, Any]],
    formulas: list[dict[str, Any]],
    case_rows: list[dict[str, Any]],
    costs: list[dict[str, Any]],
) -> str:
    """Our figure for one of the paper's headline numbers (``paper.PAPER_NUMBERS``' keys).

    Args:
        key: ``("accuracy", method)``, ``("elements", direction, method)``,
            ``("edit", scenario, method)``, ``("time", method)`` or ``("tokens", method)``;
            ``llm`` stands for every ``llm[model]`` label.
        acc: the accuracy table.
        formulas: the element-fit table.
        case_rows: the edit-distance rows.
        costs: the cost table.

    Returns:
        The figure as text, ``NOT_RUN`` when the method did not run.
    """

    def matches(method: str, wanted: str) -> bool:
        return method == wanted or (wanted == "llm" and method.startswith(("llm[", "nllm[")))

    what = key[0]
    if what == "accuracy":
        chosen = [r for r in acc if matches(r["method"], key[1]) and r["group"] == "all"]
        found = [r for r in chosen if "text" not in r and r["produced"]]
        if not found:
            return NOT_RUN
        return "; ".join(
            f"{r['method']} {_pct(r['accuracy'])} ({r['equivalent']}/{r['produced']}, "
            f"Wilson [{_pct(r['wilson_low'])}, {_pct(r['wilson_high'])}])"
            for r in found
        )
    if what == "elements":
        fit = next(
            (f for f in formulas if f["direction"] == key[1] and f["method"] == key[2]), None
        )
        if fit is None:
            return NOT_RUN
        return f"{fit['fitted_slope']:.2f}M{fit['intercept']:+.1f} (fit over {fit['n']})"
    if what == "edit":
        chosen = [c for c in case_rows if c["scenario"] == key[1] and c["method"] == key[2]]
        if not chosen:
            return NOT_RUN
        written = " / ".join(_edit_cell(c) for c in chosen)
        flat = " / ".join(
            "error" if c["flat_distance"] is None else f"{c['flat_distance']:.0f}" for c in chosen
        )
        return (
            f"{written} as written (k = {', '.join(str(c['k']) for c in chosen)}); {flat} flattened"
        )
    chosen_costs = [c for c in costs if matches(c["method"], key[1])]
    found_costs = [c for c in chosen_costs if "text" not in c]
    if not found_costs:
        return NOT_RUN
    if what == "time":
        return "; ".join(
            f"{c['method']} median {1000 * c['convert_median_s']:.1f} ms "
            f"(p95 {1000 * c['convert_p95_s']:.1f} ms)"
            for c in found_costs
        )
    return "; ".join(f"{c['method']} {c['tokens']}" for c in found_costs)


def _pct(value: float | None) -> str:
    return "–" if value is None else f"{100 * value:.1f} %"
