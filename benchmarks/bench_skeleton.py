"""Cost of the migration path's skeletons: writing them, and compiling the C++ one.

    PYTHONPATH=src python benchmarks/bench_skeleton.py [--leaves 3,30,300] [--no-compile]

For the example tree (examples/pick_place_bt.xml) and for generated trees with N leaf types (a
Sequence of N leaves, each type with three ports), it times ``fsmbt runtime cpp DIR MODEL`` and
``fsmbt runtime python DIR MODEL`` (the library call, median of 5 runs into fresh folders), a
rerun into the same folder (generated files rewritten, user files kept), and - unless
``--no-compile`` - the CMake configure and build of the C++ skeleton against the cached
BehaviorTree.CPP 4.8.2 (``fsmbt.runtime.cpp.library_prefix()``), one build each, wall and CPU
(children's user+system) seconds, under ``nice -n 10``. The machine may be shared: CPU seconds
are the stable figure. Prints one table.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from fsmbt.runtime.cpp import library_built, library_prefix
from fsmbt.runtime.skeleton import write_skeleton

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "pick_place_bt.xml"


def generated_tree(leaves: int) -> str:
    uses = "".join(f'<Leaf{i} name="L{i}" speed="1.5" target="{{goal}}"/>' for i in range(leaves))
    models = "".join(
        f'<Action ID="Leaf{i}"><input_port name="speed" type="double" default="1.0"/>'
        f'<input_port name="target"/><output_port name="result"/></Action>'
        for i in range(leaves)
    )
    return (
        '<root BTCPP_format="4" main_tree_to_execute="T"><BehaviorTree ID="T"><Sequence>'
        f"{uses}</Sequence></BehaviorTree><TreeNodesModel>{models}</TreeNodesModel></root>"
    )


def time_writes(model: Path, language: str, work: Path) -> tuple[float, float]:
    """Median seconds of a first write and of a rewrite into the same folder."""
    first, again = [], []
    for run in range(5):
        folder = work / f"{language}-{model.stem}-{run}"
        started = time.perf_counter()
        write_skeleton(model, folder, language)
        first.append(time.perf_counter() - started)
        started = time.perf_counter()
        write_skeleton(model, folder, language)
        again.append(time.perf_counter() - started)
    return statistics.median(first), statistics.median(again)


def compile_cpp(project: Path) -> tuple[float, float]:
    """Wall and CPU seconds of configuring and building the C++ skeleton."""
    before = os.times()
    started = time.perf_counter()
    for command in (
        [
            "cmake",
            "-S",
            str(project),
            "-B",
            str(project / "build"),
            f"-DCMAKE_PREFIX_PATH={library_prefix()}",
            "-DCMAKE_BUILD_TYPE=Release",
        ],
        ["nice", "-n", "10", "cmake", "--build", str(project / "build")],
    ):
        done = subprocess.run(command, capture_output=True, text=True, timeout=1800)
        if done.returncode != 0:
            raise SystemExit(f"build failed: {done.stderr[-500:]}")
    after = os.times()
    cpu = (after.children_user - before.children_user) + (
        after.children_system - before.children_system
    )
    return time.perf_counter() - started, cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--leaves", default="3,30,300", help="leaf types of the generated trees")
    parser.add_argument("--no-compile", action="store_true", help="skip the C++ builds")
    args = parser.parse_args()
    compile_too = not args.no_compile and library_built()
    header = (
        f"{'tree':<22} {'leaf types':>10} {'cpp write ms':>12} {'rewrite ms':>10} "
        f"{'py write ms':>11} {'rewrite ms':>10} {'build wall s':>12} {'build CPU s':>11}"
    )
    print(header)
    print("-" * len(header))
    with tempfile.TemporaryDirectory(prefix="fsmbt-bench-skeleton-") as tmp:
        work = Path(tmp)
        models = [("pick_place_bt.xml", EXAMPLE, 3)]
        for count in (int(n) for n in args.leaves.split(",") if n.strip()):
            path = work / f"tree{count}.xml"
            path.write_text(generated_tree(count), encoding="utf-8")
            models.append((f"generated ({count})", path, count))
        for name, path, count in models:
            cpp_first, cpp_again = time_writes(path, "cpp", work)
            py_first, py_again = time_writes(path, "python", work)
            wall = cpu = "-"
            if compile_too:
                seconds, cpu_seconds = compile_cpp(work / f"cpp-{path.stem}-0")
                wall, cpu = f"{seconds:.1f}", f"{cpu_seconds:.1f}"
            print(
                f"{name:<22} {count:>10} {cpp_first * 1e3:>12.1f} {cpp_again * 1e3:>10.1f} "
                f"{py_first * 1e3:>11.1f} {py_again * 1e3:>10.1f} {wall:>12} {cpu:>11}",
                flush=True,
            )
    if not compile_too and not args.no_compile:
        print(f"(no builds: BehaviorTree.CPP is not built at {library_prefix()})")


if __name__ == "__main__":
    main()
