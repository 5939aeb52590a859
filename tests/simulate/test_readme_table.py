"""The prediction tables of README.md and docs/validation.md are what ``rotomorph paper``
produces."""

from __future__ import annotations

from pathlib import Path

import pytest

from rotomorph.simulate.report import TABLE_END, TABLE_START, paper_rows, prediction_table

ROOT = Path(__file__).resolve().parents[2]


def _table(name: str) -> str:
    text = (ROOT / name).read_text(encoding="utf-8")
    start = text.index(TABLE_START)
    end = text.index(TABLE_END) + len(TABLE_END)
    return text[start:end]


@pytest.mark.slow
def test_readme_table_equals_the_report() -> None:
    rows, summary = paper_rows(quick=False)
    table = prediction_table(rows, summary)
    for name in ("README.md", "docs/validation.md"):
        assert _table(name) == table, (
            f"{name}'s prediction table is stale: run `rotomorph paper -o out` and paste "
            "out/prediction_table.md over it"
        )
    # the contract: fits are never counted, at least 10 out-of-sample predictions
    assert not any(r["calibration"] and r["counted"] for r in rows)
    assert summary["out_of_sample_predictions"] >= 10
