"""Generated model folders for the batch tests (FSMs as JSON, BTs as BehaviorTree.CPP XML)."""

from __future__ import annotations

from pathlib import Path

from fsmbt import api
from fsmbt.generate import DatasetSpec, generate_models


def write_models(
    folder: Path,
    n: int,
    *,
    seed: int = 7,
    max_states: int = 8,
    depth: int | None = 3,
    nested: bool = True,
) -> list[Path]:
    """Write ``n`` generated models (half FSMs, half BTs) under ``folder``.

    Args:
        folder: where to write (created); with ``nested`` the BTs go to ``folder/bt/``.
        n: how many models.
        seed: the generator's seed.
        max_states: the FSMs' size limit.
        depth: the BTs' depth (``None`` draws it).
        nested: put the BTs in a sub-folder (to check the mirrored layout).

    Returns:
        The files written, in order.
    """
    fsms = DatasetSpec("fsm", seed=seed, min_states=2, max_states=max_states)
    bts = DatasetSpec("bt", seed=seed, depth=depth, breadth=3)
    written = []
    for stem, model in generate_models(fsms, (n + 1) // 2):
        written.append(api.write(model, folder / f"{stem}.json", "json"))
    for stem, model in generate_models(bts, n // 2):
        where = folder / "bt" if nested else folder
        written.append(api.write(model, where / f"{stem}.xml", "btcpp"))
    return written
