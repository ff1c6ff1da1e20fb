"""NuSMV on the trees of issue 27's SKIPPED encoding (RunOnce ``then_skip="true"``,
``SkipUnlessUpdated``, Nav2's ``SingleTrigger``): the four trees of the agreement test's
``built-ins SKIPPED`` group, both loop modes, each with its conversion (when the rules engine
converts it), against itself and against its ``then_skip``-flipped copy (tree against tree).

Prints, per pair: the native verdict and time, NuSMV's CPU seconds (``RUSAGE_CHILDREN``: the
figure that does not depend on the machine's load) and wall seconds, NuSMV's verdict; then the
totals. Prints figures only; nothing is asserted (agreement is the test's job).

Run: ``.venv/bin/python benchmarks/bench_nusmv_skipped.py [--timeout 600]``.
"""

from __future__ import annotations

import argparse
import resource
import time

from fsmbt.convert.engines import converter_for
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError, UnsupportedError
from fsmbt.semantics.nodes import node_semantics
from fsmbt.verify import verify
from fsmbt.verify.nusmv import check
from fsmbt.verify.nusmv.runner import NuSMVLimitError


def leaf(name: str, condition: bool = False) -> BTNode:
    return BTNode(name, NodeKind.CONDITION if condition else NodeKind.ACTION, name=name)


def node(kind: str, *children: BTNode, **attrs: str) -> BTNode:
    """A registry kind (project kinds enabled as ``--nodes`` / ``--abstract`` would)."""
    spec = node_semantics(kind)
    assert spec is not None
    return BTNode(kind, spec.kind, attrs=dict(attrs), children=list(children), semantics=kind)


def trees() -> list[tuple[str, BTNode]]:
    return [
        ("Sequence(RunOnce(a), b)", node("Sequence", node("RunOnce", leaf("a")), leaf("b"))),
        (
            "ReactiveSequence(c, RunOnce(Sequence(a, b)))",
            node(
                "ReactiveSequence",
                leaf("c", True),
                node("RunOnce", node("Sequence", leaf("a"), leaf("b")), then_skip="true"),
            ),
        ),
        (
            "Sequence(SkipUnlessUpdated(a), SkipUnlessUpdated(b))",
            node(
                "Sequence",
                node("SkipUnlessUpdated", leaf("a")),
                node("SkipUnlessUpdated", leaf("b")),
            ),
        ),
        (
            "ReactiveSequence(c, SingleTrigger(a), b)",
            node("ReactiveSequence", leaf("c", True), node("SingleTrigger", leaf("a")), leaf("b")),
        ),
    ]


def flipped(root: BTNode) -> BTNode | None:
    """A copy of ``root`` with every RunOnce's ``then_skip`` flipped; None without one."""
    import copy

    copied = copy.deepcopy(root)
    stack, found = [copied], False
    while stack:
        x = stack.pop()
        if x.type == "RunOnce":
            x.attrs["then_skip"] = "false" if x.attrs.get("then_skip", "true") == "true" else "true"
            found = True
        stack.extend(x.children)
    return copied if found else None


def cpu_of_children() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timeout", type=float, default=600.0)
    args = parser.parse_args()
    print(f"{'pair':<72}{'native':>8}{'nat s':>7}{'CPU s':>7}{'wall s':>8}  NuSMV")
    total_cpu = total_wall = 0.0
    for name, root in trees():
        doc = BTDocument.single(root)
        for loop in (False, True):
            pairs: list[tuple[str, object]] = []
            try:
                options = {"loop": True} if loop else {}
                pairs.append(("conversion", converter_for("rules", doc)(doc, **options).model))
            except FsmbtError as exc:
                print(f"{name + f' loop={int(loop)} conversion':<72}  not converted: {exc}"[:140])
            pairs.append(("against itself", doc))
            other = flipped(root)
            if other is not None:
                pairs.append(("then_skip flipped", BTDocument.single(other)))
            for what, result in pairs:
                label = f"{name} loop={int(loop)} {what}"
                started = time.perf_counter()
                native = verify(doc, result, loop=loop).equivalent  # type: ignore[arg-type]
                native_s = time.perf_counter() - started
                cpu, wall = cpu_of_children(), time.perf_counter()
                try:
                    verdict = str(check(doc, result, loop=loop, timeout=args.timeout).equivalent)  # type: ignore[arg-type]
                except UnsupportedError as exc:
                    verdict = f"refused: {exc}"[:60]
                except NuSMVLimitError:
                    verdict = f"past the {args.timeout:.0f} s cap"
                cpu, wall = cpu_of_children() - cpu, time.perf_counter() - wall
                total_cpu += cpu
                total_wall += wall
                print(f"{label:<72}{native!s:>8}{native_s:>7.2f}{cpu:>7.2f}{wall:>8.2f}  {verdict}")
    print(f"NuSMV in total: {total_cpu:.1f} s CPU, {total_wall:.1f} s wall")


if __name__ == "__main__":
    main()
