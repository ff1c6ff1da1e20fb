"""Pictures of a comparison: an animated GIF of one episode, both sides next to each other, and
a PNG plot of both sides' trajectories (matplotlib, Agg backend; the GIF through Pillow).

What is drawn: the world's square and fixed places (``landmarks()``), every mover's path
(``movers``: the robot and the cube; the predator and the prey), and, when the sides diverge,
a cross at each side's positions at the first divergent step. The GIF shows each step's
positions with the behaviour of each role (the last leaf ticked, or the state's action); long
episodes are sampled down to ``MAX_FRAMES`` frames.

Costs: O(steps x movers) to draw the plot; the GIF encodes at most ``MAX_FRAMES`` frames.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fsmbt.sim.world import Divergence, StepRecord, Trajectory

MAX_FRAMES = 48
COLOURS = ("tab:blue", "tab:red", "tab:green", "tab:orange", "tab:purple")


def _short(behaviour: str) -> str:
    """The last leaf ticked (``a:S b:R => RUNNING`` -> ``b``) or the action (``e -> A`` -> A)."""
    if " -> " in behaviour:
        return behaviour.rsplit(" -> ", 1)[1]
    trail = behaviour.split(" => ")[0].split()
    return trail[-1].split(":")[0] if trail else "-"


def _frame(
    ax: Any, world: Any, record: StepRecord | None, title: str, upto: list[StepRecord]
) -> None:
    ax.clear()
    ax.set_xlim(-0.5, world.size + 0.5)
    ax.set_ylim(-0.5, world.size + 0.5)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    for name, (x, y) in world.landmarks():
        ax.plot(x, y, marker="s", color="0.6", markersize=9)
        ax.annotate(name, (x, y), fontsize=6, xytext=(3, 3), textcoords="offset points")
    # the first mover (the robot, the predator) is drawn last: on top of what it carries
    for colour, mover in reversed(list(zip(COLOURS, world.movers))):
        xs = [dict(r.positions)[mover][0] for r in upto if mover in dict(r.positions)]
        ys = [dict(r.positions)[mover][1] for r in upto if mover in dict(r.positions)]
        ax.plot(xs, ys, color=colour, linewidth=0.8, alpha=0.6)
        if xs:
            ax.plot(xs[-1], ys[-1], marker="o", color=colour, markersize=6, label=mover)
    if record is None:
        ax.set_title(f"{title}\n(episode ended)", fontsize=7)
        return
    doing = ", ".join(f"{role}: {_short(b)}" for role, b in record.behaviour)
    ax.set_title(f"{title} - step {record.step}\n{doing}", fontsize=7)


def write_gif(
    left: Trajectory,
    right: Trajectory,
    world: Any,
    path: Path,
    names: tuple[str, str] = ("model", "other"),
    fps: int = 8,
) -> Path:
    """An animated GIF of ``left`` and ``right`` side by side.

    Args:
        left: one side's trajectory.
        right: the other side's (same seed).
        world: the world they ran in (for its size, places and movers).
        path: the GIF to write.
        names: the two panels' titles.
        fps: frames per second.

    Returns:
        ``path``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation, PillowWriter

    length = max(len(left.records), len(right.records), 1)
    stride = max(1, -(-length // MAX_FRAMES))
    steps = list(range(0, length, stride))
    if steps[-1] != length - 1:
        steps.append(length - 1)
    fig, axes = plt.subplots(1, 2, figsize=(7.2, 3.8), dpi=60)

    def draw(step: int) -> list[Any]:
        for ax, trajectory, name in zip(axes, (left, right), names):
            records = trajectory.records
            record = records[step] if step < len(records) else None
            _frame(ax, world, record, name, records[: step + 1])
        axes[0].legend(loc="lower left", fontsize=6)
        return []

    animation = FuncAnimation(fig, draw, frames=steps, blit=False)
    animation.save(str(path), writer=PillowWriter(fps=fps))
    plt.close(fig)
    return path


def write_plot(
    left: Trajectory,
    right: Trajectory,
    world: Any,
    path: Path,
    names: tuple[str, str] = ("model", "other"),
    divergence: Divergence | None = None,
) -> Path:
    """A PNG of both trajectories (one panel each), the divergence marked when there is one.

    Args:
        left: one side's trajectory.
        right: the other side's.
        world: the world (size, places, movers).
        path: the PNG to write.
        names: the panels' titles.
        divergence: the first divergent step, marked with a cross on both panels.

    Returns:
        ``path``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(8, 4.2), dpi=90)
    for ax, trajectory, name in zip(axes, (left, right), names):
        last = trajectory.records[-1] if trajectory.records else None
        _frame(ax, world, last, name, trajectory.records)
        ax.set_title(
            f"{name}: {len(trajectory.records)} steps ({trajectory.ended}), seed {trajectory.seed}",
            fontsize=8,
        )
        if divergence is not None:
            record = divergence.left if trajectory is left else divergence.right
            if record is not None:
                for _mover, (x, y) in record.positions:
                    ax.plot(x, y, marker="x", color="black", markersize=9)
    axes[0].legend(loc="lower left", fontsize=7)
    if divergence is not None:
        fig.suptitle(f"first divergence at step {divergence.step}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path
