"""Sweep records are validated before a resume trusts them (schema, run id, checksum, the
sha256 of the run's HDF5 file): a damaged one is recomputed with one warning naming its file,
never a traceback and never tabled as another run."""

from __future__ import annotations

import json
import logging
import shutil
from concurrent.futures import ThreadPoolExecutor

import pytest

from rotomorph.errors import InvalidParameterError
from rotomorph.sweep import execute_run, parse_sweep, run_sweep
from rotomorph.sweep.records import MAX_RECORD_BYTES, DamagedRecord, check_record
from rotomorph.sweep.store import RunStore

DESIGN = {
    "schema_version": 1,
    "filaments": [{"spacing": 0.5, "segments": [{"kind": "line", "length": 8.0}]}],
}


def _sweep(hdf5=False, method="closed_form"):
    return parse_sweep(
        {
            "schema_version": 1,
            "design": DESIGN,
            "outputs": ["end_to_end_ratio", "morphology"],
            "settings": {"method": method, "steps": 1},
            "hdf5": hdf5,
            "parameters": [
                {"path": "filaments[0].rotation_number", "values": [0.1, 0.5, 1.0, 2.0]}
            ],
        }
    )


def _run(sweep, folder):
    """Run ``sweep`` in threads; returns (result, ids evaluated in this call)."""
    evaluated = []

    def evaluate(spec):
        evaluated.append(spec.run_id)
        return execute_run(spec)

    with ThreadPoolExecutor(2) as pool:
        result = run_sweep(sweep, folder, executor=pool, evaluate=evaluate, fsync=False)
    return result, evaluated


def _rows(result):
    return result.table.drop_columns(["wall_time_s"]).to_pylist()


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    folder = tmp_path_factory.mktemp("records") / "out"
    result, evaluated = _run(_sweep(), folder)
    assert len(evaluated) == 4
    return folder, result


def _edit_metric(path, other):
    rec = json.loads(path.read_text())
    rec["metrics"]["filaments"][0]["end_to_end_ratio"] = 0.123
    path.write_text(json.dumps(rec))


def _retag(path, other):
    """Copied under another id and its run_id rewritten: the checksum catches it."""
    rec = json.loads(other.read_text())
    rec["run_id"] = path.stem
    path.write_text(json.dumps(rec))


DAMAGE = {
    "truncated": lambda p, o: p.write_bytes(p.read_bytes()[: len(p.read_bytes()) // 2]),
    "empty": lambda p, o: p.write_bytes(b""),
    "binary": lambda p, o: p.write_bytes(bytes(range(256)) * 4),
    "copied under another id": lambda p, o: shutil.copyfile(o, p),
    "copied and retagged": _retag,
    "edited": _edit_metric,
    "no checksum": lambda p, o: p.write_text(
        json.dumps({k: v for k, v in json.loads(p.read_text()).items() if k != "checksum"})
    ),
    "oversized": lambda p, o: p.write_bytes(b" " * (MAX_RECORD_BYTES + 1) + p.read_bytes()),
    "nested": lambda p, o: p.write_bytes(b"[" * 100_000 + b"]" * 100_000),
    "not a table": lambda p, o: p.write_text("[1, 2, 3]"),
    "NaN": lambda p, o: p.write_text(p.read_text().replace('"wall_time_s": ', '"x": NaN, "w": ')),
}


@pytest.mark.parametrize("damage", list(DAMAGE), ids=list(DAMAGE))
def test_a_damaged_record_is_recomputed_with_a_warning_naming_it(
    finished, tmp_path, caplog, damage
):
    folder, first = finished
    copy = tmp_path / "out"
    shutil.copytree(folder, copy)
    store = RunStore(copy)
    ids = sorted(store.stored())
    victim, other = store.record_path(ids[1]), store.record_path(ids[2])
    DAMAGE[damage](victim, other)
    with pytest.raises(InvalidParameterError, match=ids[1][:12]):
        store.read(ids[1])  # never returned as if it were fine
    caplog.set_level(logging.WARNING, logger="rotomorph.sweep.store")
    result, evaluated = _run(_sweep(), copy)
    assert evaluated == [ids[1]], "exactly the damaged run is computed again"
    assert _rows(result) == _rows(first)
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1 and "\n" not in warnings[0]
    assert str(victim.relative_to(copy)) in warnings[0] and "computed again" in warnings[0]
    assert check_record(victim, ids[1])["run_id"] == ids[1]  # replaced by a sound one


def test_a_record_whose_results_file_is_missing_or_changed_is_recomputed(tmp_path, caplog):
    folder = tmp_path / "out"
    first, evaluated = _run(_sweep(hdf5=True, method="rod"), folder)
    assert len(evaluated) == 4
    store = RunStore(folder)
    ids = sorted(store.stored())
    store.results_path(ids[0]).unlink()
    h5 = store.results_path(ids[3])
    h5.write_bytes(h5.read_bytes()[:-1] + b"\x00")
    caplog.set_level(logging.WARNING, logger="rotomorph.sweep.store")
    result, evaluated = _run(_sweep(hdf5=True, method="rod"), folder)
    assert sorted(evaluated) == [ids[0], ids[3]]
    assert _rows(result) == _rows(first)
    text = " ".join(r.getMessage() for r in caplog.records)
    assert "is missing" in text and "does not match its sha256" in text


def test_check_record_names_the_reason(finished):
    folder, _ = finished
    store = RunStore(folder)
    run_id = sorted(store.stored())[0]
    rec = check_record(store.record_path(run_id), run_id)
    assert rec["record_format"] == 1 and len(rec["checksum"]) == 64
    with pytest.raises(DamagedRecord, match=r"belongs to run .* \(copied\?\)"):
        check_record(store.record_path(run_id), "0" * 64)


def test_overlapping_runs_give_the_library_logger_its_propagation_back(tmp_path):
    """Runs in threads silence the library's logger while they run; when all have ended it
    propagates again (it stayed silent when two runs' save/restore interleaved)."""
    logger = logging.getLogger("rotomorph")
    assert logger.propagate
    for _ in range(3):
        _run(_sweep(method="rod"), tmp_path / "out")
        assert logger.propagate
