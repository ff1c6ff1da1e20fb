"""Picture sizes of ``fsmbt render`` with default options (issue 29, "Pictures at any size").

    FSMBT_CORPUS=/work/shared/corpus nice -n 19 .venv/bin/python benchmarks/render_sizes.py
        [--sample 20] [--seed 29] [--all] [--no-generated] [FILE ...]

(For a "before" figure, run it with ``PYTHONPATH=<older checkout>/src``.)

Every model is drawn as ``fsmbt render MODEL -o x.png`` draws it (``fsmbt.render.render_model``
with its defaults) into a temporary folder, and the PNG's size is read from its header. Rows:

- every example in ``examples/`` that fsmbt reads as a model;
- the behavior-tree and state-machine files of the shared corpus (``$FSMBT_CORPUS/bt``,
  ``$FSMBT_CORPUS/fsm``), ``--sample`` of each kind drawn with ``--seed`` (``--all``: every
  file); files fsmbt does not read as a model alone (helper scripts, node models) are counted
  as ``unread`` and skipped;
- generated models (``fsmbt.generate``): BTs of about 100 and 1 000 nodes, FSMs of 100 and
  1 000 states (``--no-generated`` leaves them out);
- or only the files given.

Columns: ``nodes`` (states of an FSM, nodes of all trees of a BT document), the PNG's
``width x height`` in pixels, ``aspect`` (long side / short side), ``ok`` when the picture fits
4 096 x 4 096 pixels and its aspect is at most 4, ``scale`` (the factor Graphviz shrank the
layout by to fit its ``size`` cap, from ``dot -Tplain``: below 1 the labels are smaller than at
100 %; measured on the source the PNG was drawn from, ``ratio`` included), and the seconds the
drawing took. The last lines count the models that meet the rule and, per kind, the pictures
needing a scale below 1 (the target is 0: every picture at 100 %). Stderr notes of the renderer (what was folded, capped) are
counted in ``notes``. Nothing is written into the repository.
"""

from __future__ import annotations

import argparse
import os
import random
import struct
import sys
import tempfile
import time
from pathlib import Path

from fsmbt import api
from fsmbt.generate import random_bt, random_fsm
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import FsmbtError
from fsmbt.model.fsm import FSM
from fsmbt.render import model_to_dot, render_model, run_dot


def drawn_source(model: FSM | BTDocument) -> str:
    """The DOT source the CLI draws: measured (``picture_dot``), or on an older checkout (a
    "before" run) the plain ``model_to_dot``."""
    import fsmbt.render as render

    measured = getattr(render, "picture_dot", None)
    return str(measured(model)) if measured is not None else model_to_dot(model)


REPO = Path(__file__).resolve().parents[1]
CORPUS = Path(os.environ.get("FSMBT_CORPUS", REPO / ".." / "shared" / "corpus"))
#: The rule: each side at most this many pixels ...
MAX_SIDE = 4096
#: ... and the long side at most this many times the short one.
MAX_ASPECT = 4.0
MODEL_SUFFIXES = {".xml", ".scxml", ".json", ".csv", ".mmd", ".py", ".yaml", ".yml"}


def png_size(path: Path) -> tuple[int, int]:
    """(width, height) from a PNG's IHDR chunk (bytes 16..24 of the file)."""
    with path.open("rb") as handle:
        head = handle.read(24)
    if head[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path} is not a PNG")
    width, height = struct.unpack(">II", head[16:24])
    return width, height


def layout_scale(model: FSM | BTDocument) -> float:
    """The factor Graphviz scaled the default picture by to fit its ``size`` cap (1: drawn at
    100 %), from the first line of ``dot -Tplain`` (``graph SCALE WIDTH HEIGHT``) of the source
    the PNG was drawn from: the measured source, with ``ratio`` when it was too elongated
    (``fsmbt.render.dot.aspect_source``, where the checkout has it)."""
    import fsmbt.render.dot as dot

    source = drawn_source(model)
    patch = getattr(dot, "aspect_source", None)
    if patch is not None:
        source = patch(source, "png", run_dot(source, "png"))
    first = run_dot(source, "plain").split(b"\n", 1)[0].split()
    return float(first[1])


def model_size(model: FSM | BTDocument) -> int:
    if isinstance(model, FSM):
        return len(model.states)
    return sum(1 for _ in model.nodes())


def corpus_files(kind: str, sample: int | None, rng: random.Random) -> list[Path]:
    folder = CORPUS / kind
    if not folder.is_dir():
        return []
    files = sorted(
        p
        for p in folder.rglob("*")
        if p.is_file() and p.suffix.lower() in MODEL_SUFFIXES and "models" not in p.parts
    )
    if sample is not None and len(files) > sample:
        files = sorted(rng.sample(files, sample))
    return files


def generated() -> list[tuple[str, FSM | BTDocument]]:
    return [
        ("generated BT ~100 (seed 2)", random_bt(2, depth=6, breadth=8, max_nodes=100)),
        ("generated BT ~1000 (seed 1)", random_bt(1, depth=10, breadth=10, max_nodes=1000)),
        (
            "generated BT ~1000 extended (seed 3)",
            random_bt(3, depth=10, breadth=10, max_nodes=1000, extended=True),
        ),
        ("generated FSM 100", random_fsm(29, n_states=100)),
        ("generated FSM 1000", random_fsm(29, n_states=1000)),
    ]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("files", nargs="*", type=Path)
    parser.add_argument("--sample", type=int, default=20, help="corpus files per kind")
    parser.add_argument("--seed", type=int, default=29)
    parser.add_argument("--all", action="store_true", help="every corpus file")
    parser.add_argument("--no-generated", action="store_true")
    args = parser.parse_args(argv)
    rng = random.Random(args.seed)
    jobs: list[tuple[str, Path | FSM | BTDocument]] = []
    if args.files:
        jobs += [(str(p), p) for p in args.files]
    else:
        jobs += [
            (f"examples/{p.name}", p)
            for p in sorted((REPO / "examples").iterdir())
            if p.suffix.lower() in MODEL_SUFFIXES
        ]
        sample = None if args.all else args.sample
        for kind in ("bt", "fsm"):
            jobs += [(str(p.relative_to(CORPUS)), p) for p in corpus_files(kind, sample, rng)]
        if not args.no_generated:
            jobs += generated()
    print(
        f"{'model':<62} {'kind':>4} {'nodes':>6} {'width x height':>15} {'aspect':>6} ok  {'scale':>5}  s"
    )
    ok = drawn = unread = failed = noted = 0
    scaled = {"fsm": 0, "bt": 0}
    lowest = {"fsm": 1.0, "bt": 1.0}
    with tempfile.TemporaryDirectory() as tmp:
        for index, (name, source) in enumerate(jobs):
            if isinstance(source, Path):
                try:
                    model = api.load(source).model
                except (FsmbtError, OSError, ValueError):
                    unread += 1
                    continue
            else:
                model = source
            out = Path(tmp) / f"m{index}.png"
            notes: list[str] = []
            started = time.perf_counter()
            try:
                render_model(model, out, notes=notes)
            except FsmbtError as exc:
                failed += 1
                print(f"{name[-62:]:<62} refused: {str(exc).splitlines()[0][:80]}")
                continue
            seconds = time.perf_counter() - started
            scale = layout_scale(model)
            kind = "fsm" if isinstance(model, FSM) else "bt"
            scaled[kind] += scale < 0.999
            lowest[kind] = min(lowest[kind], scale)
            width, height = png_size(out)
            aspect = max(width, height) / max(1, min(width, height))
            fits = width <= MAX_SIDE and height <= MAX_SIDE and aspect <= MAX_ASPECT
            drawn += 1
            ok += fits
            noted += bool(notes)
            print(
                f"{name[-62:]:<62} {kind:>4} {model_size(model):>6} "
                f"{f'{width} x {height}':>15} {aspect:>6.2f} {'yes' if fits else 'NO ':<3}"
                f" {scale:>5.2f} {seconds:.1f}",
                flush=True,
            )
    print(
        f"\n{ok} of {drawn} pictures fit {MAX_SIDE} x {MAX_SIDE} with aspect <= {MAX_ASPECT:g}; "
        f"{drawn - ok} do not; {noted} drawn with a note (folded / capped); "
        f"{failed} refused; {unread} files not read as a model"
    )
    print(
        f"needing scale < 1 (labels below 100 %): {scaled['fsm']} FSM pictures (lowest scale "
        f"{lowest['fsm']:.2f}), {scaled['bt']} BT pictures (lowest {lowest['bt']:.2f})"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
