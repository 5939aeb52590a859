"""A prediction's band in parts, the weak-test rule and the score of the discriminating rows."""

from __future__ import annotations

import math

import pytest

from rotomorph.simulate.bands import WEAK_SHARE, Band, finish_row, is_weak_test, plain_row
from rotomorph.simulate.validation import row, summarise, summary_line


def _row(measured: float, spread: float, predicted: float, sd: float | None = None) -> dict:
    return row(
        "q", "c", measured, spread, predicted, predicted_sd=sd, unit="1", figure="f", note="n"
    )


def test_total_is_the_root_sum_of_squares_and_missing_parts_are_named() -> None:
    band = Band(calibration=0.03, calibration_prior=0.01, nuisance=0.04, numerical=0.0)
    assert band.total == pytest.approx(0.05)
    assert band.unconstrained == pytest.approx(math.hypot(0.01, 0.04))
    assert Band(calibration=0.1).missing() == ["nuisance", "numerical"]
    assert Band(calibration=0.1).total == pytest.approx(0.1)


def test_weak_when_more_than_half_the_combined_variance_is_unconstrained() -> None:
    # spread 0.1, nuisance just above / below the share of the combined variance
    s = 0.1
    # u^2 > share (s^2 + u^2)  <=>  u^2 > share s^2 / (1 - share)
    edge = math.sqrt(WEAK_SHARE * s**2 / (1.0 - WEAK_SHARE))
    assert is_weak_test(s, Band(nuisance=1.01 * edge))
    assert not is_weak_test(s, Band(nuisance=0.99 * edge))
    # data-constrained calibration width never makes a test weak, its prior-held part does
    assert not is_weak_test(s, Band(calibration=1.0, calibration_prior=0.0))
    assert is_weak_test(s, Band(calibration=1.0, calibration_prior=0.9))
    # the model-form (branch) choice is unconstrained too
    assert is_weak_test(s, Band(model_form=0.2))


def test_finish_row_recomputes_z_from_the_full_band() -> None:
    r = _row(1.0, 0.1, 1.3, sd=0.05)
    assert r["z"] == pytest.approx(0.3 / math.hypot(0.1, 0.05), abs=1e-3)
    out = finish_row(r, Band(calibration=0.05, nuisance=0.2, numerical=0.0), extrapolated=[])
    total = math.hypot(0.05, 0.2)
    assert out["predicted_sd"] == pytest.approx(total, abs=1e-5)
    assert out["z"] == pytest.approx(0.3 / math.hypot(0.1, total), abs=1e-3)
    assert out["sd_nuisance"] == 0.2 and out["sd_calibration"] == 0.05
    assert out["weak_test"] is True and out["extrapolated"] is False
    assert r["z"] != out["z"]  # a new dict; the input row is untouched
    far = finish_row(r, Band(calibration=0.05), extrapolated=["speed 20 mm/s > 3 mm/s"])
    assert far["extrapolated"] and far["extrapolation"] == ["speed 20 mm/s > 3 mm/s"]
    assert far["band_missing"] == ["nuisance", "numerical"]


def test_a_sign_is_weak_when_the_nuisance_samples_disagree() -> None:
    r = _row(1.0, 0.0, 1.0)
    assert finish_row(r, Band(), sign_agreement=1.0)["weak_test"] is False
    out = finish_row(r, Band(), sign_agreement=0.75)
    assert out["weak_test"] is True and out["sign_agreement"] == 0.75
    assert finish_row(r, Band())["weak_test"] is None  # not sampled: not split


def test_the_score_counts_the_discriminating_rows_separately() -> None:
    strong_hit = finish_row(_row(1.0, 0.1, 1.05), Band(calibration=0.02, nuisance=0.0))
    strong_miss = finish_row(_row(1.0, 0.1, 1.5), Band(calibration=0.02, nuisance=0.0))
    weak_hit = finish_row(_row(1.0, 0.1, 1.3), Band(calibration=0.02, nuisance=0.3))
    unsplit = plain_row(_row(1.0, 0.1, 1.02, sd=0.01))
    assert [r["weak_test"] for r in (strong_hit, strong_miss, weak_hit)] == [False, False, True]
    assert unsplit["weak_test"] is None and unsplit["sd_calibration"] == 0.01
    summary = summarise([strong_hit, strong_miss, weak_hit, unsplit])
    assert summary["out_of_sample_predictions"] == 4
    assert summary["within_2_combined_spreads"] == 3
    assert summary["discriminating_predictions"] == 2
    assert summary["discriminating_within_2"] == 1
    assert summary["fraction_discriminating_within_2"] == 0.5
    assert summary["weak_tests"] == ["q: c"] and summary["band_not_split"] == ["q: c"]
    line = summary_line(summary)
    assert "1 are weak tests" in line and "2 quantitative predictions discriminate" in line


def test_a_band_without_its_nuisance_part_is_not_split() -> None:
    # however narrow the rest, an unpropagated nuisance part leaves the verdict open
    out = finish_row(_row(1.0, 0.1, 1.05), Band(calibration=0.02, numerical=0.0))
    assert out["weak_test"] is None and out["band_missing"] == ["nuisance"]
    assert out["z"] == pytest.approx(0.05 / math.hypot(0.1, 0.02), abs=1e-3)
