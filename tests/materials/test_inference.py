"""Joint calibration: recovers known parameters from synthetic data with honest uncertainty,
and reports both modulus-ratio branches when the data cannot tell them apart."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rotomorph.errors import InvalidParameterError
from rotomorph.materials import EmpiricalThreshold, FilamentModel, load_table, predict
from rotomorph.materials.calibrate import CALIBRATION_GROUPS, paper_calibration, paper_parameters
from rotomorph.materials.inference import Group, Parameter, joint_calibrate

TRUE = FilamentModel(
    strain_model=EmpiricalThreshold(gain=2.2, threshold=0.14),
    modulus_ratio=2.5,
    passive_strain=0.03,
    resolution=32,
)


def _synthetic(rng: np.random.Generator | None) -> list[Group]:
    groups = []
    for name in CALIBRATION_GROUPS:
        table = load_table(name)
        value = predict(name, table.x, TRUE)
        if rng is not None:
            value = value + rng.normal(0.0, table.spread)
        groups.append(
            Group(name, dataclasses.replace(table, value=value), lambda m, t=table: predict(
                t.name, t.x, m))
        )  # fmt: skip
    return groups


def test_recovers_known_parameters_with_covering_uncertainty() -> None:
    params = paper_parameters()
    truth = np.array([p.coordinate(float(v)) for p, v in zip(
        params, (2.5, 2.2, 0.14, 0.03), strict=True)])  # fmt: skip
    start = dataclasses.replace(TRUE, modulus_ratio=1.0, strain_model=EmpiricalThreshold())
    z = []
    for seed in range(8):
        fit = joint_calibrate(_synthetic(np.random.default_rng(seed)), params, start).chosen
        assert fit.success
        sd = np.sqrt(np.diag(fit.covariance))
        z.append((fit.theta - truth) / sd)
    z = np.abs(np.array(z))
    # coverage of the reported 1-sd and 2-sd intervals (Gaussian: 68 % and 95 %), 32 draws
    assert np.mean(z < 1.0) > 0.45
    assert np.mean(z < 2.0) > 0.8
    assert np.max(z) < 4.5


def test_noise_free_data_give_the_truth() -> None:
    start = dataclasses.replace(TRUE, modulus_ratio=1.5, strain_model=EmpiricalThreshold())
    fit = joint_calibrate(_synthetic(None), paper_parameters(), start, branch="modulus_ratio")
    assert fit.chosen.label == "modulus_ratio >= 1"
    values = fit.chosen.values
    sd = fit.chosen.sd_coordinate
    # the weak priors pull a MAP estimate by a fraction of its sd, no more
    assert abs(np.log(values["modulus_ratio"] / 2.5)) < 0.5 * sd["modulus_ratio"]
    assert abs(values["strain_model.gain"] - 2.2) < 0.5 * sd["strain_model.gain"]
    assert abs(values["strain_model.threshold"] - 0.14) < 0.5 * sd["strain_model.threshold"]


def _printed_curvature(model: FilamentModel, speed: np.ndarray) -> np.ndarray:
    """The Janus section's natural curvature per *printed* length at ω* = 0: symmetric under
    E_a/E_p -> E_p/E_a for equal halves (Timoshenko). The measured quantity, per current
    length, is not quite (the centre line's stretch differs between the branches)."""
    from rotomorph.materials import get_material

    active, passive = get_material("lce"), get_material("acrylate")
    section = model.section(active, passive, 0.3, 0.5)
    _, kappa, _ = section.natural_strains(0.0, *model.strains(np.asarray(speed), passive))
    return kappa[:, 0]


def test_symmetric_data_report_both_branches() -> None:
    """Data that cannot tell m from 1/m: both mirror optima, equal chi2, "not distinguished"."""
    table = load_table("janus_curvature")
    value = _printed_curvature(TRUE, table.x)
    group = Group("janus_curvature", dataclasses.replace(table, value=value),
                  lambda m: _printed_curvature(m, table.x))  # fmt: skip
    prior = Parameter("modulus_ratio", 0.0, 100.0, log=True, lower=-4.6, upper=4.6)
    start = dataclasses.replace(TRUE, modulus_ratio=1.0)
    cal = joint_calibrate([group], [prior], start, branch="modulus_ratio", preferred="below",
                          preference_reason="test")  # fmt: skip
    above, below = cal.branches
    assert above.values["modulus_ratio"] == pytest.approx(2.5, rel=1e-3)
    assert below.values["modulus_ratio"] == pytest.approx(1.0 / 2.5, rel=1e-3)
    assert above.chi2_data + above.chi2_prior == pytest.approx(
        below.chi2_data + below.chi2_prior, abs=1e-6
    )
    assert "not distinguished" in cal.choice and cal.chosen is below
    record = cal.record()
    assert [b["branch"] for b in record["branches"]] == ["modulus_ratio >= 1", "modulus_ratio <= 1"]


def test_propagation_is_exact_for_a_linear_quantity() -> None:
    cal = paper_calibration(resolution=32)
    fit = cal.chosen
    k = [p.name for p in fit.parameters].index("strain_model.threshold")
    value, sd = fit.propagate(lambda m: np.array([2.0 * m.strain_model.threshold]))
    assert value[0] == pytest.approx(2.0 * fit.values["strain_model.threshold"])
    assert sd[0] == pytest.approx(2.0 * np.sqrt(fit.covariance[k, k]), rel=1e-9)


def test_leave_one_group_out_and_errors() -> None:
    cal = paper_calibration(exclude=("janus_curvature",), resolution=32)
    assert cal.groups == ("pure_lce_length", "composite_length")
    assert len(cal.branches) == 2 and cal.record()["choice"] == cal.choice
    with pytest.raises(InvalidParameterError, match="unknown groups"):
        paper_calibration(exclude=("lattice",))
    with pytest.raises(InvalidParameterError, match="at least one"):
        joint_calibrate([], [], TRUE)
    with pytest.raises(InvalidParameterError, match="log parameters"):
        joint_calibrate([], paper_parameters(), TRUE, branch="passive_strain")


@dataclasses.dataclass(frozen=True)
class _Toy:
    a: float = 0.0
    b: float = 0.0


def test_prior_held_part_of_the_band_is_exact_for_a_linear_gaussian_fit() -> None:
    """Three measurements of ``a`` (sd 0.5) and none of ``b``: the posterior variance of ``a``
    splits into the data's and the prior's parts Σ²A and Σ²P (conjugate normal model), and
    ``b``, unconstrained, is all prior."""
    from rotomorph.materials.measurements import MeasuredTable

    n, sigma, s_a, s_b = 3, 0.5, 2.0, 0.7
    table = MeasuredTable(
        "toy", ("1", "2", "3"), np.zeros(n), ("",) * n, np.array([1.0, 1.2, 0.9]),
        np.full(n, sigma), ("",) * n, ("",) * n,
    )  # fmt: skip
    group = Group("toy", table, lambda m: np.full(n, m.a))
    fit = joint_calibrate(
        [group],
        [
            Parameter("a", 0.0, s_a, lower=-50, upper=50),
            Parameter("b", 0.3, s_b, lower=-50, upper=50),
        ],
        _Toy(),
    ).chosen
    precision_data, precision_prior = n / sigma**2, 1.0 / s_a**2
    var = 1.0 / (precision_data + precision_prior)
    _, sd, sd_prior = fit.propagate_parts(lambda m: np.array([m.a, m.b, m.a + m.b]))
    assert sd[0] == pytest.approx(np.sqrt(var), rel=1e-6)
    assert sd_prior[0] == pytest.approx(np.sqrt(var**2 * precision_prior), rel=1e-6)
    assert sd[1] == pytest.approx(s_b, rel=1e-6) and sd_prior[1] == pytest.approx(s_b, rel=1e-6)
    # a sum: variances add (independent posteriors), and so do the prior parts
    assert sd_prior[2] ** 2 == pytest.approx(sd_prior[0] ** 2 + sd_prior[1] ** 2, rel=1e-6)
    # the data's part is what is left, and a measured direction is mostly data
    assert sd[0] ** 2 - sd_prior[0] ** 2 == pytest.approx(var**2 * precision_data, rel=1e-6)
    assert sd_prior[0] < 0.2 * sd[0]
