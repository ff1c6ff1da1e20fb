"""The report folder: Markdown, a self-contained HTML page, PNG/SVG plots, CSV/JSON rows.

Layout of ``<report>/``: ``report.md``, ``report.html`` (plots inlined as SVG, no external
file), ``plots/*.png|svg`` (accuracy bars with Wilson intervals, elements vs M with the formula
lines, time per model size), ``rows.csv`` / ``rows.json`` (every stored result),
``tables.json`` (every table), ``run.json`` (the exact command, versions, counts, seconds).
Every number is computed from the store by ``analysis``; a method that did not run reads
"not run: no endpoint". ``report.md``'s prose and layout are the jinja2 template
``templates/report.md.j2``; this module computes its tables' cells. Cost: O(rows) plus the plots (a second each).
"""

from __future__ import annotations

import csv
import html
import io
import json
import platform
import re
import time
from importlib import metadata
from pathlib import Path
from typing import Any

from jinja2 import Environment, FileSystemLoader, StrictUndefined

from fsmbt.evaluate import analysis, cases, inputs
from fsmbt.evaluate.dataset import Entry
from fsmbt.evaluate.execute import STORE_FILE
from fsmbt.evaluate.paper import (
    NO_PAPER_FIGURE,
    NOT_RECORDED,
    NOT_RECORDED_TABLES,
    PAPER_NUMBERS,
    paper_accuracy,
    paper_cost,
)
from fsmbt.evaluate.plan import (
    NOT_RUN,
    NUSMV_EXAMPLES,
    NUSMV_MAX_NODES,
    NUSMV_MAX_STATES,
    RULE_ENGINES,
    STRUCTURED,
    Planned,
    llm_method_names,
)
from fsmbt.evaluate.runner import BATCH_SOURCE, ResultStore
from fsmbt.verify import PROPERTIES

CONSISTENCY_MODELS = ("example_robot_bt.xml", "example_predator_fsm.csv")
#: report.md's template (prose and layout); the tables arrive as Markdown text.
_TEMPLATES = Environment(
    loader=FileSystemLoader(Path(__file__).parent / "templates"),
    autoescape=False,  # Markdown, not HTML (report.html escapes every cell itself)
    trim_blocks=True,
    lstrip_blocks=True,
    keep_trailing_newline=True,
    undefined=StrictUndefined,
)
VERSIONED = ("fsmbt", "networkx", "matplotlib", "lxml", "zss", "py-trees", "behaviortreepy")


def _versions() -> dict[str, str]:
    found = {"python": platform.python_version()}
    for name in VERSIONED:
        try:
            found[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            found[name] = "not installed"
    return found


def _pct(value: float | None) -> str:
    return "–" if value is None else f"{100 * value:.1f} %"


def _md_table(header: list[str], body: list[list[Any]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in body]
    return "\n".join(lines)


def _plots(
    folder: Path,
    acc: list[dict[str, Any]],
    measured: list[dict[str, Any]],
    formulas: list[dict[str, Any]],
) -> dict[str, str]:
    """Draw the three figures; return name -> inline SVG text."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder.mkdir(parents=True, exist_ok=True)
    svgs: dict[str, str] = {}

    def save(fig: Any, name: str) -> None:
        fig.tight_layout()
        fig.savefig(folder / f"{name}.png", dpi=110)
        fig.savefig(folder / f"{name}.svg")
        buffer = io.StringIO()
        fig.savefig(buffer, format="svg")
        svgs[name] = re.sub(r"^.*?(<svg)", r"\1", buffer.getvalue(), flags=re.S)
        plt.close(fig)

    fig, ax = plt.subplots(figsize=(8, 3.6))
    groups = [g for g in (*analysis.GROUPS, "all")]
    width = 0.8 / len(RULE_ENGINES)
    for i, method in enumerate(RULE_ENGINES):
        xs, ys, lo, hi = [], [], [], []
        for j, group in enumerate(groups):
            row = next((r for r in acc if r["method"] == method and r["group"] == group), None)
            if row is None or row.get("accuracy") is None:
                continue
            xs.append(j + i * width)
            ys.append(100 * row["accuracy"])
            lo.append(max(0.0, 100 * (row["accuracy"] - row["wilson_low"])))
            hi.append(max(0.0, 100 * (row["wilson_high"] - row["accuracy"])))
        ax.bar(xs, ys, width, yerr=[lo, hi], capsize=3, label=method)
    ax.set_xticks([j + width for j in range(len(groups))], groups)
    ax.set_ylabel("verified equivalent (%)")
    ax.set_ylim(0, 105)
    ax.set_title("Accuracy per scenario, Wilson 95 % intervals (LLM methods: not run)")
    ax.legend(loc="lower right")
    save(fig, "accuracy")

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, direction in zip(axes, ("fsm->bt", "bt->fsm")):
        for method in RULE_ENGINES:
            chosen = [r for r in measured if r["direction"] == direction and r["method"] == method]
            if not chosen:
                continue
            points = ax.scatter(
                [r["M"] for r in chosen],
                [r["graphical"] for r in chosen],
                s=6,
                alpha=0.5,
                label=f"{method} measured",
            )
            fit = next(f for f in formulas if f["direction"] == direction and f["method"] == method)
            top = max(r["M"] for r in chosen)
            ax.plot(
                [0, top],
                [0, fit["paper_slope"] * top],
                color=points.get_facecolor()[0],
                linestyle="--",
                label=f"{method} paper {fit['paper_formula']}",
            )
        ax.set_xlabel("M (FSM states)" if direction == "fsm->bt" else "M (BT leaves)")
        ax.set_ylabel("graphical elements of the result")
        ax.set_title(direction)
        ax.legend(fontsize=7)
    save(fig, "elements")

    fig, ax = plt.subplots(figsize=(7, 3.6))
    for method in RULE_ENGINES:
        chosen = [r for r in measured if r["method"] == method]
        ax.scatter(
            [r["source_graphical"] for r in chosen],
            [1000 * r["seconds"] for r in chosen],
            s=6,
            alpha=0.5,
            label=method,
        )
    ax.set_xlabel("source model size (graphical elements)")
    ax.set_ylabel("conversion time (ms)")
    ax.set_yscale("log")
    ax.set_title("Time per conversion vs model size")
    ax.legend()
    save(fig, "time")
    return svgs


def write_report(
    settings: Any,
    entries: list[Entry],
    planned: list[Planned],
    llm_models: list[str],
    summary: dict[str, Any],
) -> Path:
    """Compute every table and write the report folder; return ``report.md``'s path."""
    out: Path = settings.output
    store = ResultStore(out / STORE_FILE)
    try:
        stored = store.results()
    finally:
        close = getattr(store, "close", None)
        if close is not None:
            close()
    table_rows = analysis.rows(planned, stored, entries)
    llm_methods = llm_method_names(llm_models) if llm_models else llm_method_names(["default"])
    methods = [*RULE_ENGINES, STRUCTURED, *llm_methods]
    acc = analysis.accuracy(table_rows, methods)
    consistency = analysis.consistency(
        table_rows, [*RULE_ENGINES, *llm_methods[:2]], CONSISTENCY_MODELS
    )
    measured = analysis.element_rows(table_rows)
    formulas = analysis.formula_table(measured)
    costs = analysis.cost(table_rows, [*RULE_ENGINES, STRUCTURED, *llm_methods[:2]])
    nusmv = analysis.nusmv_table(table_rows)
    nusmv_models = analysis.nusmv_sample_rows(table_rows, entries)
    examples = settings.examples or Path("examples")
    case_rows = [
        c.to_row()
        for c in cases.measure(examples, out / "cases", timeout=2.0 if settings.quick else 5.0)
    ]
    representation = inputs.table(examples, out / "inputs", llm_methods[:2])
    svgs = _plots(out / "plots", acc, measured, formulas)
    headlines = [
        {
            "figure": what,
            "paper": value,
            "ours": analysis.headline(key, acc, formulas, case_rows, costs),
            "source": source,
        }
        for what, value, source, key in PAPER_NUMBERS
    ]
    tables = {
        "accuracy": acc,
        "consistency": consistency,
        "formulas": formulas,
        "edit_distances": case_rows,
        "input_representation": representation,
        "cost": costs,
        "nusmv_sample": nusmv,
        "nusmv_models": nusmv_models,
        "paper": headlines,
        "retry_statistics": NOT_RUN,
        "version_sensitivity": NOT_RUN,
    }
    run = {
        "command": settings.command,
        "versions": _versions(),
        "batch_runner": BATCH_SOURCE,
        "seed": settings.seed,
        "per_scenario_and_kind": settings.per_kind,
        "quick": settings.quick,
        "nusmv_sample": settings.nusmv_sample,
        "workers": settings.workers,
        "llm_models": llm_models or NOT_RUN,
        "models": len(entries),
        "jobs": len(planned),
        "rows_stored": len(table_rows),
        "run_seconds": round(summary.get("run_seconds", 0.0), 1),
        "written_at": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime()),
    }
    runs_file = out / "runs.jsonl"
    run["invocations"] = (
        [json.loads(line) for line in runs_file.read_text().splitlines() if line.strip()]
        if runs_file.exists()
        else []
    )
    (out / "tables.json").write_text(json.dumps(tables, indent=1, default=str) + "\n")
    (out / "run.json").write_text(json.dumps(run, indent=1) + "\n")
    (out / "rows.json").write_text(json.dumps(table_rows, default=str) + "\n")
    with open(out / "rows.csv", "w", newline="", encoding="utf-8") as stream:
        columns = [
            "key",
            "model",
            "group",
            "kind",
            "source",
            "method",
            "verifier",
            "status",
            "verdict",
            *PROPERTIES,
            "convert_s",
            "verify_s",
            "error_class",
            "error_message",
            "output",
        ]
        writer = csv.DictWriter(stream, fieldnames=columns, extrasaction="ignore")
        writer.writeheader()
        for r in table_rows:
            writer.writerow(
                {
                    **r,
                    **r["properties"],
                    "convert_s": r["timings"].get("convert"),
                    "verify_s": r["timings"].get("verify"),
                }
            )
    markdown = markdown_report(
        run,
        entries,
        acc,
        consistency,
        formulas,
        case_rows,
        representation,
        costs,
        nusmv,
        nusmv_models,
        headlines,
    )
    (out / "report.md").write_text(markdown, encoding="utf-8")
    (out / "report.html").write_text(_html(markdown, svgs), encoding="utf-8")
    return out / "report.md"


def markdown_report(
    run: dict[str, Any],
    entries: list[Entry],
    acc: list[dict[str, Any]],
    consistency: list[dict[str, Any]],
    formulas: list[dict[str, Any]],
    case_rows: list[dict[str, Any]],
    representation: list[dict[str, Any]],
    costs: list[dict[str, Any]],
    nusmv: list[dict[str, Any]],
    nusmv_models: list[dict[str, Any]],
    headlines: list[dict[str, str]],
) -> str:
    """``report.md``: the tables' cells computed here, the prose and layout in the template
    ``templates/report.md.j2``."""
    sources: dict[str, int] = {}
    for e in entries:
        label = f"{e.source} {e.kind}" + ("" if e.readable else " (unreadable)")
        sources[label] = sources.get(label, 0) + 1
    examples_in = [m["model"] for m in nusmv_models if m["source"] == "example"]
    generated_in = [m for m in nusmv_models if m["source"] == "generated"]
    tables = {
        "invocations": _md_table(
            ["finished", "stored before", "ran", "stored after", "jobs", "seconds"],
            [
                [i["finished_at"], i["before"], i["ran"], i["after"], i["jobs"], i["seconds"]]
                for i in run["invocations"]
            ],
        ),
        "dataset": _md_table(
            ["source / kind", "models"], [[k, v] for k, v in sorted(sources.items())]
        ),
        "accuracy": _md_table(
            [
                "method",
                "group",
                "equivalent/produced",
                "accuracy",
                "Wilson 95 %",
                "not produced",
                "paper",
            ],
            _accuracy_rows(acc),
        ),
        "consistency": _md_table(
            ["model", "method", *PROPERTIES, "paper"], _consistency_rows(consistency)
        ),
        "formulas": _md_table(
            [
                "direction",
                "method",
                "n",
                "paper",
                "fitted a (graphical)",
                "b",
                "fitted a (active)",
                "mean dev. from ours",
                "within band",
            ],
            _formula_rows(formulas),
        ),
        "cases": _md_table(
            [
                "scenario",
                "case",
                "method",
                "BT edit",
                "FSM edit, as written",
                "bounds",
                "FSM edit, flattened",
                "paper",
                "k",
                "Δ elements",
                "verified",
            ],
            _case_rows(case_rows),
        ),
        "inputs": _md_table(
            ["representation", "file", "method", "read by", "result", "paper"],
            [
                [
                    r["representation"],
                    r["file"],
                    r["method"],
                    r.get("reader", ""),
                    r.get("text", ""),
                    NOT_RECORDED,
                ]
                for r in representation
            ],
        ),
        "cost": _md_table(
            [
                "method",
                "n",
                "convert median",
                "convert p95",
                "verify median",
                "paper time",
                "tokens",
                "paper tokens",
            ],
            _cost_rows(costs),
        ),
        "nusmv": _md_table(
            [
                "method",
                "sampled",
                "both equivalent",
                "not equivalent",
                "not encodable / error",
                "reasons",
            ],
            [
                [
                    n["method"],
                    n["sampled"],
                    n["both_equivalent"],
                    n["not_equivalent"],
                    n["not_encodable_or_error"],
                    "; ".join(n["reasons"]),
                ]
                for n in nusmv
            ],
        ),
        "nusmv_models": _md_table(
            ["model", "source", "kind", "size", *RULE_ENGINES],
            [
                [
                    m["model"],
                    m["source"],
                    m["kind"],
                    m["size"],
                    *[
                        f"{m.get(e, '–')} ({m[e + '_seconds']:.1f} s)"
                        if m.get(e + "_seconds") is not None
                        else m.get(e, "–")
                        for e in RULE_ENGINES
                    ],
                ]
                for m in nusmv_models
            ],
        ),
        "headlines": _md_table(
            ["figure", "paper", "ours", "source"],
            [[h["figure"], h["paper"], h["ours"], h["source"]] for h in headlines],
        ),
    }
    return _TEMPLATES.get_template("report.md.j2").render(
        run=run,
        versions=", ".join(f"{k} {v}" for k, v in run["versions"].items()),
        tables=tables,
        not_run=NOT_RUN,
        not_recorded=NOT_RECORDED,
        not_recorded_tables=NOT_RECORDED_TABLES,
        no_paper_figure=NO_PAPER_FIGURE,
        formula_band=f"{analysis.FORMULA_BAND:.0%}",
        nusmv_examples=", ".join(NUSMV_EXAMPLES),
        examples_in=", ".join(examples_in) or "none",
        generated_in=len(generated_in),
        nusmv_max_states=NUSMV_MAX_STATES,
        nusmv_max_nodes=NUSMV_MAX_NODES,
    )


def _accuracy_rows(acc: list[dict[str, Any]]) -> list[list[Any]]:
    body: list[list[Any]] = []
    for row in acc:
        if "text" in row:
            if row["group"] == "all":
                body.append(
                    [
                        row["method"],
                        "every group",
                        row["text"],
                        "",
                        "",
                        "",
                        paper_accuracy(row["method"]),
                    ]
                )
            continue
        body.append(
            [
                row["method"],
                row["group"],
                f"{row['equivalent']}/{row['produced']}",
                _pct(row["accuracy"]),
                f"[{_pct(row['wilson_low'])}, {_pct(row['wilson_high'])}]",
                f"{row['refused']} refused, {row['bad_input']} unreadable, {row['error']} errors",
                paper_accuracy(row["method"]),
            ]
        )
    return body


def _consistency_rows(consistency: list[dict[str, Any]]) -> list[list[Any]]:
    body: list[list[Any]] = []
    for row in consistency:
        if "text" in row:
            body.append(
                [row["model"], row["method"], *[row["text"]] * len(PROPERTIES), NOT_RECORDED]
            )
        else:
            body.append(
                [
                    row["model"],
                    row["method"],
                    *["✓" if row[p] else ("✗" if row[p] is False else "–") for p in PROPERTIES],
                    NOT_RECORDED,
                ]
            )
    return body


def _formula_rows(formulas: list[dict[str, Any]]) -> list[list[Any]]:
    return [
        [
            f["direction"],
            f["method"],
            f["n"],
            f["paper_formula"],
            f"{f['fitted_slope']:.2f} ± {f['slope_error']:.2f}",
            f"{f['intercept']:.1f}",
            f"{f['active_slope']:.2f} ± {f['active_slope_error']:.2f}",
            _pct(f["mean_deviation_from_ours"]),
            _pct(f["within_band"]),
        ]
        for f in formulas
    ]


def _case_rows(case_rows: list[dict[str, Any]]) -> list[list[Any]]:
    return [
        [
            c["scenario"],
            c["case"],
            c["method"],
            c["bt_edit"],
            ("–" if c["distance"] is None else f"{'' if c['exact'] else '≤ '}{c['distance']:.0f}"),
            (
                "exact"
                if c["exact"]
                else f"[{c['lower_bound']:.0f}, {c['distance']:.0f}]"
                if c["distance"] is not None and c["lower_bound"] is not None
                else "–"
            ),
            (
                "–"
                if c["flat_distance"] is None
                else f"{'' if c['flat_exact'] else '≤ '}{c['flat_distance']:.0f}"
            ),
            c["paper"],
            f"{c['k_base']} → {c['k']}",
            c["extended_graphical"] - c["base_graphical"],
            c["verified"] if not c["error"] else c["error"],
        ]
        for c in case_rows
    ]


def _cost_rows(costs: list[dict[str, Any]]) -> list[list[Any]]:
    body: list[list[Any]] = []
    for c in costs:
        paper_time, paper_tokens = paper_cost(c["method"])
        if "text" in c:
            body.append([c["method"], "–", c["text"], "", "", paper_time, c["text"], paper_tokens])
        else:
            body.append(
                [
                    c["method"],
                    c["n"],
                    f"{1000 * c['convert_median_s']:.1f} ms",
                    f"{1000 * c['convert_p95_s']:.1f} ms",
                    f"{1000 * c['verify_median_s']:.1f} ms",
                    paper_time,
                    c["tokens"],
                    paper_tokens,
                ]
            )
    return body


def _html(markdown: str, svgs: dict[str, str]) -> str:
    """A self-contained page: the Markdown's tables as HTML, the plots inlined as SVG."""
    body: list[str] = []
    lines = markdown.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("|"):
            rows = []
            while i < len(lines) and lines[i].startswith("|"):
                if not set(lines[i]) <= set("|-"):
                    rows.append([html.escape(c.strip()) for c in lines[i].strip("|").split(" | ")])
                i += 1
            head, *rest = rows
            body.append(
                "<table><tr>"
                + "".join(f"<th>{c}</th>" for c in head)
                + "</tr>"
                + "".join("<tr>" + "".join(f"<td>{c}</td>" for c in r) + "</tr>" for r in rest)
                + "</table>"
            )
            continue
        figure = re.match(r"!\[(\w+)\]", line)
        if figure:
            body.append(f"<figure>{svgs.get(figure.group(1), '')}</figure>")
        elif line.startswith("## "):
            body.append(f"<h2>{html.escape(line[3:])}</h2>")
        elif line.startswith("# "):
            body.append(f"<h1>{html.escape(line[2:])}</h1>")
        elif line.strip():
            body.append(f"<p>{html.escape(line)}</p>")
        i += 1
    style = (
        "body{font-family:sans-serif;max-width:70em;margin:auto}table{border-collapse:"
        "collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:2px 6px;font-size:90%}"
        "figure svg{max-width:100%;height:auto}"
    )
    return (
        "<!DOCTYPE html><html><head><meta charset='utf-8'><title>fsmbt evaluation</title>"
        f"<style>{style}</style></head><body>{''.join(body)}</body></html>\n"
    )
