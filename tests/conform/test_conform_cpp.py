"""fsmbt conform on logs BehaviorTree.CPP 4.8.2 writes itself in fsmbt's C++ driver: its
``FileLogger2`` (.btlog) and ``SqliteLogger`` (.db3, the build has ``BTCPP_SQLITE_LOGGING=ON``).
The driver's scripted mode runs the tree with every leaf scripted from a seed; its LEBT mode runs
a converted state machine on events. A tree's logs conform to it, a mutant's are caught with the
node named, and a .db3 that is not a BT.CPP SQLite log, or of another tree, is exit 2."""

from __future__ import annotations

import shutil
import sqlite3
import subprocess
from pathlib import Path

import pytest

from fsmbt import api, conform
from fsmbt.cli import main
from fsmbt.formats import dumps
from fsmbt.model.errors import InputError
from fsmbt.runtime.cpp import find_driver
from fsmbt.verify import verify
from fsmbt.verify.mutations import mutants
from support.btlog_record import record_cpp

ROOT = Path(__file__).resolve().parents[2]
ROBOT = ROOT / "examples" / "robot_bt.xml"
SWAP = ("<RobotAtInspection/>\n        <Dock/>", "<Dock/>\n        <RobotAtInspection/>")
SEEDS = range(3)
TICKS = 30

pytestmark = pytest.mark.skipif(
    find_driver() is None, reason="the C++ driver is built by scripts/setup.sh"
)


def _record(tmp_path: Path, xml_path: Path, seed: int, name: str = "run") -> tuple[Path, Path]:
    btlog, db3 = tmp_path / f"{name}{seed}.btlog", tmp_path / f"{name}{seed}.db3"
    record_cpp(xml_path, seed=seed, ticks=TICKS, btlog=btlog, db3=db3)
    return btlog, db3


def test_both_logs_of_the_tree_conform_and_agree(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    runs = [_record(tmp_path, ROBOT, seed) for seed in SEEDS]
    files = [str(p) for run in runs for p in run]
    assert main(["conform", str(ROBOT), *files]) == 0
    out = capsys.readouterr().out
    assert out.count(": conforms (") == len(files)
    for btlog, db3 in runs:
        a, b = conform.read_log(btlog), conform.read_log(db3)
        assert (a.format, b.format) == ("btlog", "db3")
        # the two loggers saw the same run: the same transitions, node for node
        assert len(b) > 0
        assert [a.nodes[u].path for u in a.uids] == [b.nodes[u].path for u in b.uids]
        assert a.statuses == b.statuses
        assert b.times == sorted(b.times) and b.start_us > 0
    report = conform.conform_files(ROBOT, [db3 for _, db3 in runs])
    assert all(r.leaf_ticks > 0 for r in report.results)
    seen, total = report.coverage.transitions
    assert 0 < seen <= total == 6 * 2 + 6 * 3  # six conditions, six actions


def test_swapped_fallback_is_caught_in_both_logs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    swapped = tmp_path / "swapped.xml"
    swapped.write_text(ROBOT.read_text(encoding="utf-8").replace(*SWAP), encoding="utf-8")
    caught = 0
    for seed in SEEDS:
        logs = _record(tmp_path, swapped, seed, "swapped")
        assert conform.conform_files(swapped, list(logs)).conforms  # its own model
        results = conform.conform_files(ROBOT, list(logs)).results
        found = [r.deviation for r in results]
        assert (found[0] is None) == (found[1] is None)  # same run, same verdict
        for deviation in found:
            if deviation is not None:
                caught += 1
                assert deviation.node == "Dock@2/0", deviation.text()
                assert "RobotAtInspection@2/0" in deviation.allowed
    assert caught
    btlog, db3 = _record(tmp_path, swapped, 0, "cli")
    code = main(["conform", str(ROBOT), str(db3)])
    out = capsys.readouterr().out
    if code == 1:
        assert f"{db3}: DEVIATES at transition #" in out and "node Dock@2/0" in out
    else:
        assert code == 0 and f"{db3}: conforms" in out


def test_mutants_db3_logs_against_the_source(tmp_path: Path) -> None:
    model = api.load(ROBOT).model
    caught = 0
    for k, mutant in enumerate(mutants(model, seed=5, per_operator=1)):
        path = api.write(mutant.model, tmp_path / f"m{k}.xml")
        logs = []
        for seed in range(2):
            db3 = tmp_path / f"m{k}_{seed}.db3"
            record_cpp(path, seed=seed, ticks=TICKS, db3=db3)
            logs.append(db3)
        assert conform.conform_files(path, logs).conforms, mutant.description
        against_source = conform.conform_files(ROBOT, logs)
        if verify(model, mutant.model).equivalent:
            assert against_source.conforms, mutant.description
        elif not against_source.conforms:
            caught += 1
    assert caught >= 2


def test_lebt_run_on_events_logs_conform(tmp_path: Path) -> None:
    """The driver's LEBT mode with --btlog/--db3: its printed steps are those of a run without
    logs, and the logs conform to the tree it ran."""
    from fsmbt.convert import convert

    driver = find_driver()
    assert driver is not None
    tree = tmp_path / "door_bt.xml"
    door = api.load(ROOT / "examples" / "door_hfsm.scxml").model
    tree.write_text(dumps(convert(door, style="lebt").model, "btcpp"), encoding="utf-8")
    events = "open_cmd\nfully_open\nfire_alarm\nopen_cmd\nreset\nfire_alarm\nshutdown\n"
    btlog, db3 = tmp_path / "door.btlog", tmp_path / "door.db3"

    def run(*extra: str) -> str:
        done = subprocess.run(
            [str(driver), str(tree), *extra], input=events, capture_output=True, text=True
        )
        assert done.returncode == 0, done.stderr
        return done.stdout

    assert run("--btlog", str(btlog), "--db3", str(db3)) == run()
    report = conform.conform_files(tree, [btlog, db3])
    assert report.conforms, [r.deviation for r in report.results]
    assert all(r.leaf_ticks > 0 for r in report.results)
    a, b = conform.read_log(btlog), conform.read_log(db3)
    assert a.statuses == b.statuses and len(b) > 0


# -- bad .db3 files ------------------------------------------------------------------------------
def _edited(tmp_path: Path, source: Path, name: str, *statements: str) -> Path:
    bad = tmp_path / name
    shutil.copyfile(source, bad)
    with sqlite3.connect(bad) as db:
        for statement in statements:
            db.execute(statement)
    db.close()
    return bad


def test_bad_db3_files(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _, good = _record(tmp_path, ROBOT, 0)
    data = good.read_bytes()
    other = tmp_path / "other.db3"
    with sqlite3.connect(other) as db:
        db.execute("CREATE TABLE results (id INTEGER)")
    db.close()
    cut = tmp_path / "cut.db3"
    cut.write_bytes(data[: len(data) // 2])
    garbage = tmp_path / "garbage.db3"
    garbage.write_bytes(data[:100] + b"\xa5" * (len(data) - 100))
    _, prey = _record(tmp_path, ROOT / "examples" / "prey_bt.xml", 0, "prey")
    cases = {
        other: "not a BehaviorTree.CPP SqliteLogger log: it has no table",
        cut: "corrupt SQLite database",
        garbage: "",
        _edited(
            tmp_path,
            good,
            "view.db3",
            "ALTER TABLE Transitions RENAME TO T2",
            "CREATE VIEW Transitions AS SELECT * FROM T2",
        ): "it has no table Transitions",
        _edited(
            tmp_path, good, "columns.db3", "ALTER TABLE Nodes ADD COLUMN x"
        ): "table Nodes has columns",
        _edited(tmp_path, good, "empty.db3", "DELETE FROM Definitions"): "holds no session",
        _edited(
            tmp_path,
            good,
            "uid.db3",
            "UPDATE Transitions SET node_uid = 999 WHERE timestamp = "
            "(SELECT MAX(timestamp) FROM Transitions)",
        ): "node UID 999 is not in the session's tree",
        _edited(
            tmp_path,
            good,
            "state.db3",
            "UPDATE Transitions SET state = 9 WHERE timestamp = "
            "(SELECT MIN(timestamp) FROM Transitions)",
        ): "state 9 is not a BehaviorTree.CPP NodeStatus",
        _edited(
            tmp_path, good, "text.db3", "UPDATE Transitions SET state = 'x'"
        ): "must be integers",
        _edited(tmp_path, good, "xml.db3", "UPDATE Definitions SET xml_tree = '<root'"): "xml.db3",
        prey: "another tree",
    }
    for bad, words in cases.items():
        assert main(["conform", str(ROBOT), str(bad)]) == 2, bad.name
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and str(bad) in err[0] and words in err[0], (bad.name, err)
    # the reader never writes: the file is unchanged after a read
    before = good.read_bytes()
    conform.read_logs(good)
    assert good.read_bytes() == before


def test_two_sessions_are_two_logs(tmp_path: Path) -> None:
    _, first = _record(tmp_path, ROBOT, 0)
    _, second = _record(tmp_path, ROBOT, 1, "second")
    both = _edited(
        tmp_path,
        first,
        "both.db3",
        f"ATTACH DATABASE '{second}' AS s",
        "INSERT INTO Definitions (session_id, date, xml_tree) "
        "SELECT 2, date, xml_tree FROM s.Definitions",
        "INSERT INTO Nodes SELECT 2, fullpath, node_uid FROM s.Nodes",
        "INSERT INTO Transitions SELECT timestamp + 1000000000, 2, node_uid, duration, state, "
        "extra_data FROM s.Transitions",
    )
    logs = conform.read_logs(both)
    assert [log.path for log in logs] == [f"{both}#session=1", f"{both}#session=2"]
    assert logs[0].statuses == conform.read_log(first).statuses
    assert logs[1].statuses == conform.read_log(second).statuses
    assert conform.conform_files(ROBOT, [both]).conforms
    with pytest.raises(InputError, match="holds 2 sessions"):
        conform.read_log(both)
