"""ResultStore: one row per key, claims, done and retry, summary; rows survive reopening."""

from __future__ import annotations

from pathlib import Path

from fsmbt.batch import Job, JobResult, ResultStore


def test_rows_round_trip_and_replace_by_key(tmp_path: Path) -> None:
    row = JobResult(
        "k1",
        "a.xml",
        "equivalent",
        verdict="EQUIVALENT",
        properties={"reachability": True},
        timings={"total": 0.5},
        output="out/a.scxml",
        stats={"product_states": 12},
        options={"loop": True},
    )
    with ResultStore(tmp_path) as store:
        store.put(row)
        store.put(
            JobResult(
                "k2",
                "b.xml",
                "bad_input",
                error_class="InputError",
                error_message="b.xml:3: not well-formed",
            )
        )
        store.put(
            JobResult(
                "k2",
                "b.xml",
                "bad_input",
                error_class="InputError",
                error_message="b.xml:4: not well-formed",
            )
        )
    with ResultStore(tmp_path) as store:  # reopened: everything committed is there
        results = {r.key: r for r in store.results()}
        assert set(results) == {"k1", "k2"}
        assert results["k1"].properties == {"reachability": True}
        assert results["k1"].stats == {"product_states": 12} and results["k1"].seconds == 0.5
        assert results["k2"].error_message == "b.xml:4: not well-formed"
        assert store.done("k1") and store.done("k2") and not store.done("k3")
        summary = store.summary()
        assert summary["statuses"]["equivalent"] == 1 and summary["statuses"]["bad_input"] == 1
        assert summary["total"] == 2 and summary["bytes"] > 0


def test_claims_are_pending_until_a_result_and_never_replace_a_result(tmp_path: Path) -> None:
    a = tmp_path / "a.json"
    a.write_text("{}", encoding="utf-8")
    job = Job(str(a), str(tmp_path / "a.xml"))
    with ResultStore(tmp_path / "s.sqlite") as store:
        store.claim([job])
        assert store.pending_output(job.key) and not store.done(job.key)
        assert store.results() == [] and store.summary()["pending"] == 1
        store.put(JobResult(job.key, job.input, "equivalent"))
        store.claim([job])  # a later claim keeps the finished row
        assert store.done(job.key) and not store.pending_output(job.key)


def test_retryable_rows_are_stored_but_not_done(tmp_path: Path) -> None:
    with ResultStore(tmp_path) as store:
        store.put(
            JobResult(
                "k",
                "x.json",
                "error",
                error_class="LLMUnavailableError",
                error_message="HTTP 503",
                retry=True,
            )
        )
        assert not store.done("k")
        assert store.summary()["retry"] == 1
        assert [r.error_message for r in store.results()] == ["HTTP 503"]
