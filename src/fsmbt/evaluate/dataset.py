"""The evaluation's dataset: seeded generated models plus the real ones, with a manifest.

Rules:
- Per scenario (``basic``, ``robot``, ``game``: the vocabulary of names) ``n`` FSMs of 2-30
  states, the structures taken in turn (``chain``, ``tree`` = branches, ``loop``), and ``n``
  BTs of depth and breadth drawn in [2, 10]. Model ``i`` of a run with seed ``S`` is drawn from
  ``"<S>:<i>"`` (``fsmbt.generate.DatasetSpec``), so a run of 10 is the first 10 of a run of
  200 and the same seed gives byte-identical files on every machine.
- The real models are the files of ``examples/`` that a reader claims and every model file of
  the corpus (``FSMBT_CORPUS``, default ``../shared/corpus``) when it is present. They are read
  where they lie, never copied; the manifest names their path and hash.
- Generated models are written as fsmbt JSON under ``<out>/dataset/``; a file already there
  with the same content is left alone (a resumed run writes nothing).
- The manifest (``manifest.json`` and ``manifest.csv``): id, scenario, kind, source, seed,
  shape, path, size figures (states, transitions / nodes, depth, leaves; graphical and active
  elements) and sha256 of the file. A real file no reader accepts stays in the manifest with
  ``readable = false`` and the reader's error: it becomes a ``bad_input`` row, not a gap.

Cost: O(total model size); the reading of real models dominates (a second or so for the corpus).
"""

from __future__ import annotations

import csv
import hashlib
import json
import os
from collections.abc import Iterable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from fsmbt import api
from fsmbt.formats import dumps
from fsmbt.generate import SCENARIOS, DatasetSpec
from fsmbt.metrics import elements
from fsmbt.model.errors import FsmbtError

#: FSM structures, taken in turn (``tree`` is the generator's name for branching structures).
FSM_STRUCTURES = ("chain", "tree", "loop")
#: Files of the corpus that are models (SCION ``.json`` traces and notes are not).
CORPUS_EXTENSIONS = (".xml", ".scxml", ".py")
EXAMPLE_SCENARIOS = {
    "robot_bt": "robot",
    "game_npc_bt": "game",
    "guard_npc": "game",
    "predator_fsm": "game",
    "delivery_smach": "robot",
}
#: What a full run generates per scenario and kind (the paper's 200).
FULL_COUNT = 200


@dataclass
class Entry:
    """One model of the dataset (one manifest row)."""

    id: str
    scenario: str
    kind: str
    source: str  # "generated", "example" or "corpus"
    path: str
    sha256: str
    seed: str | None = None
    shape: str | None = None
    readable: bool = True
    error: str | None = None
    size: dict[str, int] = field(default_factory=dict)

    def to_row(self) -> dict[str, Any]:
        """A flat row for the CSV manifest (size figures as ``size_<name>`` columns)."""
        row = {k: v for k, v in asdict(self).items() if k != "size"}
        for name in SIZE_FIGURES:
            row[f"size_{name}"] = self.size.get(name)
        return row


SIZE_FIGURES = ("states", "transitions", "nodes", "depth", "leaves", "graphical", "active")


def sha256_of(path: Path) -> str:
    """The file's SHA-256 in hex."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


def size_of(model: api.Model) -> dict[str, int]:
    """The size figures of a model (``SIZE_FIGURES``; FSM counts include every level)."""
    e = elements(model)
    figures = {"graphical": e.graphical, "active": e.active, "depth": e.depth}
    if e.kind == "fsm":
        figures.update(states=e.states, transitions=e.transitions)
    else:
        figures.update(nodes=e.nodes, leaves=e.leaves)
    return figures


def _write_if_changed(path: Path, text: str) -> None:
    if path.exists() and path.read_text(encoding="utf-8") == text:
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.tmp")
    temporary.write_text(text, encoding="utf-8")
    os.replace(temporary, path)


def generated(outdir: Path, seed: int, count: int) -> list[Entry]:
    """Write the generated models of every scenario; return their entries.

    Args:
        outdir: the dataset folder.
        seed: the run's base seed.
        count: models per scenario and kind.

    Returns:
        The entries, FSMs then BTs per scenario.
    """
    entries = []
    for scenario in SCENARIOS:
        specs = {shape: DatasetSpec("fsm", scenario, seed, shape=shape) for shape in FSM_STRUCTURES}
        for index in range(count):
            shape = FSM_STRUCTURES[index % len(FSM_STRUCTURES)]
            spec = specs[shape]
            entries.append(_generated_entry(outdir, spec, index, shape))
        bt_spec = DatasetSpec("bt", scenario, seed)
        for index in range(count):
            entries.append(_generated_entry(outdir, bt_spec, index, None))
    return entries


def _generated_entry(outdir: Path, spec: DatasetSpec, index: int, shape: str | None) -> Entry:
    spec.check()
    model = spec.model(index)
    stem = spec.file_stem(index)
    path = outdir / "models" / spec.scenario / f"{stem}.json"
    _write_if_changed(path, dumps(model, "json"))
    return Entry(
        stem,
        spec.scenario,
        spec.kind,
        "generated",
        str(path),
        sha256_of(path),
        seed=f"{spec.seed}:{index}",
        shape=shape,
        size=size_of(model),
    )


def real_entry(path: Path, source: str, scenario: str, ident: str) -> Entry:
    """The entry of a real model file, read with fsmbt's readers (never executed)."""
    entry = Entry(ident, scenario, "?", source, str(path), sha256_of(path))
    try:
        loaded = api.load(path)
    except (FsmbtError, RecursionError, MemoryError, UnicodeDecodeError, ValueError) as exc:
        entry.readable = False
        entry.error = " ".join(str(exc).split())[:300] or type(exc).__name__
        return entry
    entry.kind = loaded.kind
    entry.size = size_of(loaded.model)
    return entry


def example_files(examples: Path) -> list[Path]:
    """The model files of ``examples/`` (scripts and notes left out)."""
    picked = []
    for path in sorted(examples.iterdir()):
        if path.suffix in (".md",) or path.name.startswith("run_"):
            continue
        if path.is_file():
            picked.append(path)
    return picked


def corpus_files(corpus: Path, limit: int | None = None) -> list[Path]:
    """Every model file of the corpus (sorted; the first ``limit`` when given)."""
    files = sorted(
        p
        for p in corpus.rglob("*")
        if p.is_file() and p.suffix in CORPUS_EXTENSIONS and "LICENSES" not in p.parts
    )
    return files[:limit] if limit is not None else files


def real(examples: Path | None, corpus: Path | None, corpus_limit: int | None) -> list[Entry]:
    """The entries of the examples and the corpus (each absent folder gives none)."""
    entries = []
    if examples is not None and examples.is_dir():
        for path in example_files(examples):
            stem = path.name.split(".")[0]
            entries.append(
                real_entry(
                    path, "example", EXAMPLE_SCENARIOS.get(stem, "basic"), f"example_{path.name}"
                )
            )
    if corpus is not None and corpus.is_dir():
        for path in corpus_files(corpus, corpus_limit):
            relative = path.relative_to(corpus).as_posix()
            entries.append(
                real_entry(path, "corpus", "corpus", "corpus_" + relative.replace("/", "__"))
            )
    return entries


def write_manifest(outdir: Path, entries: Iterable[Entry], settings: dict[str, Any]) -> Path:
    """Write ``manifest.json`` (settings + entries) and ``manifest.csv``; return the JSON path."""
    entries = list(entries)
    outdir.mkdir(parents=True, exist_ok=True)
    _write_if_changed(
        outdir / "manifest.json",
        json.dumps({"settings": settings, "models": [asdict(e) for e in entries]}, indent=1) + "\n",
    )
    with open(outdir / "manifest.csv.tmp", "w", newline="", encoding="utf-8") as stream:
        writer = csv.DictWriter(stream, fieldnames=list(entries[0].to_row()) if entries else [])
        writer.writeheader()
        for entry in entries:
            writer.writerow(entry.to_row())
    os.replace(outdir / "manifest.csv.tmp", outdir / "manifest.csv")
    return outdir / "manifest.json"


def build(
    outdir: Path,
    *,
    seed: int,
    count: int,
    examples: Path | None,
    corpus: Path | None,
    corpus_limit: int | None = None,
) -> list[Entry]:
    """Build the whole dataset and its manifest.

    Args:
        outdir: the dataset folder (``<report>/dataset``).
        seed: the base seed.
        count: generated models per scenario and kind.
        examples: the examples folder, or ``None``.
        corpus: the corpus folder, or ``None`` (absent: no corpus models).
        corpus_limit: at most this many corpus files (``--quick``).

    Returns:
        Every entry, generated first.
    """
    entries = generated(outdir, seed, count) + real(examples, corpus, corpus_limit)
    write_manifest(
        outdir,
        entries,
        {
            "seed": seed,
            "count_per_scenario_and_kind": count,
            "examples": str(examples) if examples else None,
            "corpus": str(corpus) if corpus else None,
            "corpus_limit": corpus_limit,
        },
    )
    return entries
