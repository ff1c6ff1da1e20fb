"""make_jobs: folders, globs, the mirrored layout, name clashes, what a folder walk takes, keys."""

from __future__ import annotations

from pathlib import Path

import pytest

from fsmbt.batch import Job, make_jobs
from fsmbt.model.errors import InputError
from support.batch_models import write_models

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_a_folder_is_mirrored_under_outdir(tmp_path: Path) -> None:
    files = write_models(tmp_path / "in", 4)
    jobs = make_jobs([tmp_path / "in"], tmp_path / "out")
    assert sorted(j.input for j in jobs) == sorted(str(f) for f in files)
    outputs = {Path(j.input).name: Path(j.output or "") for j in jobs}
    fsm = files[0]
    bt = files[-1]
    assert outputs[fsm.name] == tmp_path / "out" / f"{fsm.stem}.xml"  # FSM -> btcpp
    assert outputs[bt.name] == tmp_path / "out" / "bt" / f"{bt.stem}.scxml"  # BT -> scxml


def test_a_folder_walk_skips_prose_that_no_reader_claims_and_the_outdir(tmp_path: Path) -> None:
    write_models(tmp_path, 2, nested=False)
    (tmp_path / "README.md").write_text("# notes\n\nnot a model\n", encoding="utf-8")
    (tmp_path / "data.bin").write_bytes(b"\x00\x01")
    out = tmp_path / "out"
    write_models(out, 2, seed=99, nested=False)  # results of an earlier run, inside the input
    jobs = make_jobs([tmp_path], out)
    names = sorted(Path(j.input).name for j in jobs)
    assert len(names) == 2 and "README.md" not in names and "data.bin" not in names
    assert all(not Path(j.input).is_relative_to(out) for j in jobs)


def test_a_named_file_is_always_a_job_even_when_no_reader_claims_it(tmp_path: Path) -> None:
    readme = tmp_path / "README.md"
    readme.write_text("# notes\n", encoding="utf-8")
    jobs = make_jobs([readme, tmp_path / "missing.xml"], tmp_path / "out")
    assert [Path(j.input).name for j in jobs] == ["README.md", "missing.xml"]


def test_globs_and_name_clashes(tmp_path: Path) -> None:
    jobs = make_jobs([str(EXAMPLES / "paper_fsm.*")], tmp_path / "out")
    outputs = sorted(Path(j.output or "").name for j in jobs)
    assert outputs == ["paper_fsm.json.xml", "paper_fsm.xml.xml"]
    with pytest.raises(InputError, match="no file matches"):
        make_jobs([str(tmp_path / "nothing*.xml")], tmp_path / "out")


def test_to_names_the_extension_and_an_unknown_format_fails_once(tmp_path: Path) -> None:
    jobs = make_jobs([EXAMPLES / "robot_bt.xml"], tmp_path / "out", to="json")
    assert jobs[0].output is not None and jobs[0].output.endswith("robot_bt.json")
    with pytest.raises(InputError, match="unknown format"):
        make_jobs([EXAMPLES / "robot_bt.xml"], tmp_path / "out", to="nope")


def test_the_key_follows_content_and_settings_but_not_the_limits(tmp_path: Path) -> None:
    model = tmp_path / "m.json"
    model.write_text((EXAMPLES / "paper_fsm.json").read_text(encoding="utf-8"), encoding="utf-8")
    base = Job(str(model), str(tmp_path / "m.xml"))
    assert Job(str(model), str(tmp_path / "m.xml"), options={"timeout_s": 5}).key == base.key
    assert Job(str(model), str(tmp_path / "m.xml"), options={"loop": True}).key != base.key
    assert Job(str(model), str(tmp_path / "m.xml"), engine="bsd").key != base.key
    model.write_text(model.read_text(encoding="utf-8").replace('"A"', '"Z"'), encoding="utf-8")
    assert Job(str(model), str(tmp_path / "m.xml")).key != base.key
