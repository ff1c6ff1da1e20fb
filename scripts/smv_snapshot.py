"""Write the NuSMV encoder's SMV text for a sample of models, one file per model, so a refactor
of the encoder (issue 25: the rules moved into verify/nusmv/families/) can be shown to leave the
output byte-identical: run it on the code before and after and ``diff -r`` the two folders.

    FSMBT_CORPUS=/work/shared/corpus PYTHONPATH=<checkout>/src \
        .venv/bin/python scripts/smv_snapshot.py OUTDIR

Run from a checkout's root (its tests/ supply the models); ``PYTHONPATH`` picks the fsmbt
sources encoded (e.g. a ``git worktree`` of the commit before the change). The sample: every
pair of tests/verify/nusmv/test_nsmv_agreement.py's groups (``FSMBT_NUSMV_PAIRS``, default here
60, generated pairs; the corpus when ``FSMBT_CORPUS`` exists) through ``build_model``; the
example and corpus BTs alone through ``LeafBTEncoder`` in both loop modes; 140 seeded random
trees over every kind the registry says is encoded, both loop modes. A refusal is written as
its message, so error text is compared too. Prints the counts and which encoded kinds no
encoded random tree contains. Costs: about 20 s with the corpus, 3 s without.
"""

from __future__ import annotations

import importlib
import os
import random
import sys
from collections import Counter
from pathlib import Path

from fsmbt import api
from fsmbt.model.bt import BehaviorTree, BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError
from fsmbt.semantics.nodes import all_nodes
from fsmbt.verify.nusmv import build_model
from fsmbt.verify.nusmv.encode_bt import LeafBTEncoder
from fsmbt.verify.nusmv.smv import Symbols

os.environ.setdefault("FSMBT_NUSMV_PAIRS", "60")  # read when the test module is imported
sys.path[:0] = ["tests/verify/nusmv", "tests"]
agr = importlib.import_module("test_nsmv_agreement")

out = Path(sys.argv[1])
out.mkdir(parents=True, exist_ok=True)
count = Counter()


def save(label: str, text: str) -> None:
    name = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in label)
    path = out / f"{count['all']:05d}-{name[:80]}.smv"
    path.write_text(text)
    count["all"] += 1


def pair(label, source, result, loop) -> None:
    try:
        text, names, _ = build_model(source, result, loop=loop)
        save(label, text + "\n".join(names))
        count["pair-text"] += 1
    except FsmbtError as exc:
        save(label, f"ERROR {type(exc).__name__}: {exc}")
        count["pair-error"] += 1


def tree(label, doc, loop) -> None:
    try:
        enc = LeafBTEncoder(doc, "m", Symbols("in_"), Symbols("out_"), loop=loop).encode()
        save(label, enc.text + repr(enc.identity if hasattr(enc, "identity") else ""))
        count["tree-text"] += 1
        for t in doc.trees.values():
            stack = [t.root]
            while stack:
                n = stack.pop()
                kinds[n.type] += 1
                stack.extend(n.children)
    except (FsmbtError, KeyError) as exc:
        save(label, f"ERROR {type(exc).__name__}: {exc}")
        count["tree-error"] += 1


notes: Counter[str] = Counter()
kinds: Counter[str] = Counter()
groups = [
    ("gen", agr.generated_pairs()),
    ("abs", agr.abstraction_pairs()),
    ("bi", agr.builtin_pairs()),
    ("skip", agr.skip_pairs()),
    ("ex", agr.example_pairs(notes)),
    ("corpus", agr.corpus_pairs(notes)),
    ("mut", agr.mutation_suite_pairs()),
]
for gname, items in groups:
    for item in items:
        if isinstance(item, agr.Pair):
            pair(f"{gname}-{item.label}", item.source, item.result, item.loop)
        else:
            save(f"{gname}-rejected-{item.label}", f"REJECTED {item.reason}")

# the example and corpus (FSMBT_CORPUS) BTs themselves, both loop modes
for group, paths in (
    ("example", sorted(Path("examples").iterdir())),
    ("corpus", agr.corpus_files() if agr.CORPUS.is_dir() else []),
):
    for path in paths:
        try:
            model = api.load(path).model
        except FsmbtError:
            continue
        if isinstance(model, BTDocument):
            for loop in (False, True):
                tree(f"{group}-{path.name}-loop{int(loop)}", model, loop)

# -- random trees over every encoded kind ---------------------------------------------------
KINDS = [n for n in all_nodes() if n.nusmv and n.nusmv != "internal_leaf"]
rng = random.Random(25)
counter = iter(range(10**6))


def leaf(cond=None):
    i = next(counter)
    if cond is None:
        cond = rng.random() < 0.4
    r = rng.random()
    if r < 0.06:
        return BTNode(rng.choice(["AlwaysSuccess", "AlwaysFailure"]), NodeKind.ACTION)
    return BTNode(f"L{i % 4}", NodeKind.CONDITION if cond else NodeKind.ACTION, name=f"l{i}")


def attrs_for(spec, nkids):
    r = spec.nusmv
    name = spec.name
    if r == "repeat":
        return {"num_cycles": str(rng.choice([-1, 0, 1, 2, 3]))}
    if r == "retry":
        return {"num_attempts": str(rng.choice([-1, 0, 1, 2, 3]))}
    if r == "run_once":
        return {"then_skip": rng.choice(["true", "false"])}
    if r == "parallel":
        valid = [v for v in range(-nkids - 1, nkids + 1) if v < 0 or v <= nkids]
        return {"success_count": str(rng.choice(valid)), "failure_count": str(rng.choice(valid))}
    if r == "parallel_all":
        valid = [v for v in range(-nkids - 1, nkids + 1) if v < 0 or v <= nkids]
        return {"max_failures": str(rng.choice(valid))}
    if r == "manual_selector":
        return {"repeat_last_selection": rng.choice(["true", "false"])}
    if r == "recovery":
        return {"number_of_retries": str(rng.choice([0, 1, 2, 3]))}
    if r == "round_robin":
        return {"wrap_around": rng.choice(["true", "false"])}
    if r == "repeat_each_tick":
        return {"num_cycles": str(rng.choice([-1, 1, 2, 3]))}
    if r == "loop_queue":
        q = rng.choice(["{q}", "", "1;2", "1;2;3", "1"])
        if name == "LoopBool":
            q = rng.choice(["{q}", "", "true;false", "true"])
        if name == "LoopString":
            q = rng.choice(["{q}", "a;b", "a"])
        return {
            "queue": q,
            "value": "{v}",
            "if_empty": rng.choice(["SUCCESS", "FAILURE", "SKIPPED"]),
        }
    if name == "Precondition":
        return {"if": "x", "else": rng.choice(["SUCCESS", "FAILURE", "RUNNING", "SKIPPED"])}
    if name in ("SkipUnlessUpdated", "WaitValueUpdate"):
        return {"entry": "{e}"}
    if name == "Delay":
        return {"delay_msec": "5"}
    if name in ("Timeout", "Sleep"):
        return {"msec": "5"}
    if name.startswith("BlackboardCheck"):
        return {
            "value_A": "{x}",
            "value_B": "1",
            "return_on_mismatch": rng.choice(["FAILURE", "SUCCESS", "RUNNING"]),
        }
    if r == "for_each":
        return {"vector_in": "{v}", "out": "{o}"}
    return {}


def build(budget, depth, subtrees):
    if budget <= 1 or depth > 3:
        return leaf()
    spec = rng.choice(KINDS)
    r = spec.nusmv
    if spec.kind is NodeKind.SUBTREE:
        sid = f"Sub{len(subtrees)}"
        subtrees[sid] = build(budget - 1, depth + 1, subtrees)
        return BTNode("SubTree", NodeKind.SUBTREE, attrs={"ID": sid})
    if spec.kind is NodeKind.ACTION:  # Sleep
        return BTNode(spec.name, NodeKind.ACTION, attrs=attrs_for(spec, 0), semantics=spec.name)
    if spec.kind is NodeKind.DECORATOR:
        kids = [build(budget - 1, depth + 1, subtrees)]
    else:
        if r == "recovery":
            parts = 2
        elif r in ("if_then_else", "while_do_else"):
            parts = rng.choice([2, 3])
        else:
            parts = rng.randint(1 if r == "manual_selector" else 2, 3)
        kids = [build(max(1, (budget - 1) // parts), depth + 1, subtrees) for _ in range(parts)]
        if r in ("if_then_else", "while_do_else") and rng.random() < 0.7:
            kids[0] = leaf(True)
    return BTNode(
        spec.name, spec.kind, attrs=attrs_for(spec, len(kids)), children=kids, semantics=spec.name
    )


made = 0
while made < 140:
    subtrees: dict[str, BTNode] = {}
    root = build(rng.randint(3, 9), 0, subtrees)
    doc = BTDocument.single(root)
    for sid, body in subtrees.items():
        doc.trees[sid] = BehaviorTree(sid, body)
    for loop in (False, True):
        tree(f"rand{made}-loop{int(loop)}", doc, loop)
    made += 1

print(dict(count), dict(notes))
missing = [n.name for n in KINDS if kinds[n.name] == 0]
print(
    "kinds encoded in some tree:", len(KINDS) - len(missing), "of", len(KINDS), "missing:", missing
)
