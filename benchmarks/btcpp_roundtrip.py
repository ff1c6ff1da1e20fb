"""The corpus's BehaviorTree.CPP files translated by fsmbt: what of the user's file survives
(prints the figures of docs/corpus.md, "BehaviorTree.CPP files kept as written").

For each BT file of the corpus (no option: profiles found by themselves, as a user runs it):

- ``--to btcpp`` (v4 -> v4 round trip, v3 -> v4 translation) through ``fsmbt.api.translate``
  (read, write, read back, proven equivalent): is the output the source byte for byte; else
  was the user's file edited (``fsmbt.formats.btcpp.preserve``) or rewritten by the writer;
  are its comments all there, in order; how many of its lines are unchanged;
- ``--to btcpp3``: written and proven equivalent, or refused (by the first v4-only node or
  pre-condition named); each written file checked against BehaviorTree.CPP 3.8's rules
  (``fsmbt.formats.btcpp.v3_rules``); losses named.

Run: FSMBT_CORPUS=../shared/corpus PYTHONPATH=src python benchmarks/btcpp_roundtrip.py
Cost: two translations (each with its equivalence proof) per file; a few minutes.
"""

from __future__ import annotations

import difflib
import re
import sys
import tempfile
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import btcpp_loads  # noqa: E402
from corpus_coverage import corpus_files, corpus_root  # noqa: E402

from fsmbt import api  # noqa: E402
from fsmbt.formats.btcpp.v3_rules import v3_problems  # noqa: E402
from fsmbt.formats.btcpp.xml_format import write_btcpp  # noqa: E402
from fsmbt.formats.registry import read_text  # noqa: E402
from fsmbt.model.errors import FsmbtError  # noqa: E402

_COMMENT = re.compile(r"<!--.*?-->", re.S)
_V3_CAUSE = re.compile(
    r"(\w+) is a BehaviorTree\.CPP v4 node|pre-condition (_\w+)|v3's (\w+ .*?ancestor \w+)"
)


def _lines_kept(before: str, after: str) -> tuple[int, int]:
    a, b = before.splitlines(), after.splitlines()
    matcher = difflib.SequenceMatcher(None, a, b, autojunk=False)
    return sum(block.size for block in matcher.get_matching_blocks()), len(a)


def _loads(text: str, name: str) -> bool:
    """Whether BehaviorTree.CPP 4.8.2 loads a written (self-contained) file
    (``btcpp_loads.refusal``: unknown nodes registered as dummies of their declared kind)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / name
        path.write_text(text, encoding="utf-8")
        return btcpp_loads.refusal(path, Path(tmp), {}) is None


def main() -> int:
    root = corpus_root()
    files = [
        p for p, _s, kind in corpus_files(root) if kind == "bt" and "_malformed" not in p.parts
    ]
    rows: Counter[str] = Counter()
    refused_v4: Counter[str] = Counter()
    kept_lines = total_lines = 0
    rewritten: list[str] = []
    not_loaded: list[str] = []
    lost_comments: list[str] = []
    v3_rows: Counter[str] = Counter()
    v3_causes: Counter[str] = Counter()
    v3_files: dict[str, list[str]] = {}
    for path in files:
        original = read_text(path)
        v3 = 'BTCPP_format="4"' not in original
        group = "v3" if v3 else "v4"
        rows[f"{group} files"] += 1
        comments = _COMMENT.findall(original)
        try:
            loaded, result, report = api.translate(path, to="btcpp")
        except FsmbtError as exc:
            message = str(exc).replace(str(path), "").replace(str(root), "corpus")
            refused_v4[f"{path.name}: {message[:110]}"] += 1
            continue
        if report is None or not report.equivalent:
            continue
        rows[f"{group} translated"] += 1
        text = result.text
        if text == original:
            rows[f"{group} byte-identical"] += 1
        elif text != write_btcpp(loaded.model):
            rows[f"{group} edited"] += 1
        else:  # the writer's text: the user's file could not be kept (an <include>...)
            rows[f"{group} rewritten"] += 1
            rewritten.append(path.name)
        if comments:
            rows[f"{group} with comments"] += 1
            same = _COMMENT.findall(text) == comments
            rows[f"{group} comments kept"] += same
            if not same:
                lost_comments.append(path.name)
        if btcpp_loads.available():
            rows[f"{group} source loads"] += btcpp_loads.refusal(path, path.parent, {}) is None
            loads = _loads(text, path.name)
            rows[f"{group} output loads"] += loads
            if not loads:
                not_loaded.append(path.name)
        kept, lines = _lines_kept(original, text)
        rows[f"{group} only insertions"] += text != original and kept == lines
        kept_lines += kept
        total_lines += lines
        try:
            _l3, result3, report3 = api.translate(path, to="btcpp3")
        except FsmbtError as exc:
            cause = _V3_CAUSE.search(str(exc))
            name = next((g for g in cause.groups() if g), "") if cause else str(exc)[-60:]
            name = re.sub(r" (goes|runs|retries) .*ancestor", " under", name)
            v3_causes[name] += 1
            v3_files.setdefault(name, []).append(path.name)
            v3_rows["refused"] += 1
            continue
        if report3 is None or not report3.equivalent:
            continue
        v3_rows["written"] += 1
        v3_rows["rule check clean"] += not v3_problems(result3.text)
        v3_rows["with losses"] += bool(result3.losses)
    print(f"BT files of the corpus (not _malformed): {len(files)}")
    for group in ("v4", "v3"):
        n, done = rows[f"{group} files"], rows[f"{group} translated"]
        print(
            f"{group} -> v4: {done}/{n} translated and proven equivalent; "
            f"{rows[f'{group} byte-identical']} byte-identical, "
            f"{rows[f'{group} edited']} the user's file edited ({rows[f'{group} only insertions']} "
            "of them only by insertions: every source line kept), "
            f"{rows[f'{group} rewritten']} rewritten by the writer; comments kept in "
            f"{rows[f'{group} comments kept']}/{rows[f'{group} with comments']} files with comments"
        )
    if btcpp_loads.available():
        for group in ("v4", "v3"):
            print(
                f"{group} -> v4 files BehaviorTree.CPP 4.8.2 loads: "
                f"{rows[f'{group} output loads']}/{rows[f'{group} translated']} written "
                f"(their sources: {rows[f'{group} source loads']})"
            )
        print(f"  written files it refuses: {', '.join(not_loaded) or 'none'}")
    print(f"lines of the translated files unchanged: {kept_lines}/{total_lines}")
    print(f"  rewritten: {', '.join(rewritten) or 'none'}")
    print(f"  comments not kept: {', '.join(lost_comments) or 'none'}")
    for cause, count in refused_v4.most_common():
        print(f"  not translated, {count} file(s): {cause}")
    print(
        f"--to btcpp3: {v3_rows['written']} written and proven equivalent "
        f"({v3_rows['rule check clean']} pass the v3 rule check, {v3_rows['with losses']} with "
        f"named losses), {v3_rows['refused']} refused"
    )
    for cause, count in v3_causes.most_common():
        print(f"  refused, {count} file(s): {cause} ({', '.join(v3_files[cause])})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
