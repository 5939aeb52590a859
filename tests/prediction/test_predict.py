"""``rotomorph predict``: closed-form answers on the report's calibrated curves, with its band,
the settings for a wanted shape, lattice estimates labelled as such, extrapolation said."""

from __future__ import annotations

import contextlib
import io
import json

import numpy as np
import pytest

from rotomorph.cli import main
from rotomorph.errors import InvalidParameterError
from rotomorph.io.designfile import parse_design
from rotomorph.materials.calibrate import filament_shapes, janus_curvature
from rotomorph.prediction import predict_design, settings_for
from rotomorph.prediction.band import calibration_fit
from rotomorph.simulate.report import calibrated_model


@pytest.fixture(scope="module")
def report_model():
    """The model of the report's calibrated curves (Fig. 2D, 2F/G)."""
    return calibrated_model()[0]


def _filament(speed: float, rotation_number: float = 0.0, **kw) -> dict:
    return {
        "speed": speed,
        "rotation_number": rotation_number,
        "start": [10.0, 10.0, 0.0],
        "segments": [{"kind": "line", "length": 20.0}],
        **kw,
    }


def _run(argv: list[str]) -> tuple[int, str]:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(argv)
    return code, out.getvalue()


@pytest.mark.parametrize(
    "request_",
    [
        {"curvature": 0.4},
        {"twist": 0.5},
        {"L/L0": 0.5},
        {"pitch": -3.0},
        {"radius": 2.0, "pitch": 3.0},
        {"curvature": 0.4, "speed": 2.0},
    ],
    ids=str,
)
def test_settings_for_a_shape_agree_with_the_report_curve_to_1e6(report_model, request_):
    answer = settings_for(request_)
    v, w = answer.speed.value, answer.rotation_number.value
    shape = filament_shapes(report_model, np.array([w]), 0.5, speed=v)[0]
    got = {
        "curvature": shape.curvature,
        "twist": shape.torsion,
        "L/L0": shape.end_to_end_ratio,
        "radius": shape.radius,
        "pitch": shape.pitch,
    }
    for name, value in request_.items():
        if name in got:
            assert got[name] == pytest.approx(value, abs=1e-6), name
    if "curvature" in request_ and len(request_) == 1:  # Fig. 2D's curve itself, at ω* = 0
        assert w == 0.0
        assert float(janus_curvature(report_model, np.array([v]))[0]) == pytest.approx(
            0.4, abs=1e-6
        )
    # the printable setting: rounded to what a machine realises, and what it gives
    p = answer.printable
    assert p["speed"] == pytest.approx(round(v, 2), abs=1e-12)
    assert p["rotation_number"] == pytest.approx(round(w, 3), abs=1e-12)
    for name in request_:
        if name in got:
            assert answer.achieved[name].value == pytest.approx(request_[name], rel=0.02, abs=0.01)
    assert answer.speed.sd is not None and answer.rotation_number.sd is not None
    # handedness follows the sign convention: ω* > 0 left-handed (twist < 0)
    if p["rotation_number"] != 0:
        assert answer.handedness == ("left-handed" if p["rotation_number"] > 0 else "right-handed")


def test_the_band_is_the_report_calibration_posterior():
    """The sd of a predicted number is the calibration covariance propagated: compared with
    an independent linearisation, sqrt(g C g) with g by central differences in the fit
    coordinates (secants over one sd and a tangent agree to a few per cent)."""
    fit = calibration_fit()
    design = parse_design({"schema_version": 1, "filaments": [_filament(1.75)]})
    (pred,) = predict_design(design).filaments
    sd = pred.quantities["curvature"].sd

    def k(theta):
        return float(janus_curvature(fit.model_at(theta), np.array([1.75]))[0])

    h = 1e-5
    g = np.array(
        [(k(fit.theta + h * e) - k(fit.theta - h * e)) / (2 * h) for e in np.eye(len(fit.theta))]
    )
    linear = float(np.sqrt(g @ fit.covariance @ g))
    assert sd == pytest.approx(linear, rel=0.05)
    assert 0.005 < sd < 0.1


def test_predict_design_is_the_report_curve(report_model):
    design = parse_design(
        {
            "schema_version": 1,
            "filaments": [_filament(v) for v in (0.25, 1.75, 3.0)]
            + [_filament(3.0, 0.06, active_fraction=0.5), _filament(3.0, 1.0, active_fraction=1.0)],
        }
    )
    preds = predict_design(design).filaments
    k = janus_curvature(report_model, np.array([0.25, 1.75, 3.0]))
    for p, value in zip(preds[:3], k, strict=True):
        assert p.method.startswith("closed form (section")
        assert p.quantities["curvature"].value == pytest.approx(value, rel=1e-6)
        assert p.morphology == "ring" and p.quantities["L/L0"].value == 0.0
    comp = filament_shapes(report_model, np.array([0.06]), 0.5)[0]
    pure = filament_shapes(report_model, np.array([1.0]), 1.0)[0]
    assert preds[3].quantities["L/L0"].value == pytest.approx(comp.end_to_end_ratio, rel=1e-6)
    assert preds[4].quantities["L/L0"].value == pytest.approx(pure.end_to_end_ratio, rel=1e-6)
    assert preds[3].handedness == "left-handed" and preds[3].morphology == "coil"
    assert not any(p.extrapolated for p in preds)


def test_the_sign_convention_is_the_rod_solvers():
    """ω* > 0 is left-handed in rotomorph predict and in the rod solver's heated shape."""
    from rotomorph.analysis.shape import fit_helix
    from rotomorph.materials.natural import natural_field
    from rotomorph.rod.model import Model
    from rotomorph.solve.static import solve_static

    design = parse_design({"schema_version": 1, "filaments": [_filament(3.0, 0.25)]})
    (pred,) = predict_design(design).filaments
    prog = design.to_programs()[0]
    eq = solve_static(Model.from_field(prog.points, natural_field(prog)))
    assert pred.handedness == "left-handed" and pred.quantities["twist"].value < 0
    assert fit_helix(eq.positions).handedness == -1


def test_predict_command_text_and_json(tmp_path):
    path = tmp_path / "janus.toml"
    path.write_text(
        'schema_version = 1\n[[filaments]]\nname = "slow"\nspeed = 0.5\nrotation = 0.0\n'
        'start = [10.0, 10.0, 0.0]\nsegments = [{kind = "line", length = 30.0}]\n',
        encoding="utf-8",
    )
    code, text = _run(["predict", str(path)])
    assert code == 0
    line = text.splitlines()[1]
    assert line.startswith("slow: ring: curvature 0.234 ± ") and "EXTRAPOLATED" not in line
    code, text = _run(["predict", str(path), "--json"])
    record = json.loads(text)  # strict JSON: no NaN or Infinity
    q = record["filaments"][0]["quantities"]
    assert set(q) == {"curvature", "twist", "radius", "pitch", "L/L0"}
    assert q["curvature"]["sd_calibration"] > 0 and record["extrapolated"] is False
    assert record["calibrated_range"]["speed_mm_s"] == [0.25, 3.0]


def test_outside_the_calibrated_range_is_said_on_the_line_and_in_json(tmp_path):
    path = tmp_path / "fast.toml"
    path.write_text(
        "schema_version = 1\n[[filaments]]\nspeed = 20.0\nstart = [10.0, 10.0, 0.0]\n"
        'segments = [{kind = "line", length = 30.0}]\n',
        encoding="utf-8",
    )
    code, text = _run(["predict", str(path)])
    assert code == 0
    assert "EXTRAPOLATED: speed 20 mm/s outside the calibrated 0.25-3 mm/s" in text
    code, text = _run(["predict", str(path), "--json"])
    fil = json.loads(text)["filaments"][0]
    assert fil["extrapolated"] is True and "speed 20" in fil["extrapolation"][0]
    code, text = _run(["predict", str(path), "--temperature", "150"])
    assert "the calibration is at 175 °C" in text


def test_a_shape_no_setting_gives_is_refused_with_the_reachable_range(report_model, capsys):
    top = float(janus_curvature(report_model, np.array([3.0]))[0])
    with pytest.raises(InvalidParameterError, match=f"reaches 0.01709 to {top:.4g} 1/mm"):
        settings_for({"curvature": 1.0})
    assert main(["predict", "--for", "curvature=1.0"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "no print setting in the calibrated range" in err
    for bad in ("curvature", "curvature=abc", "colour=2", "curvature=0.4,curvature=0.3"):
        assert main(["predict", "--for", bad]) == 2
    assert main(["predict", "--for", "radius=2", "--for", "pitch=3", "--for", "twist=1"]) == 2
    assert main(["predict", "--for", "curvature=0.4,speed=20"]) == 2  # outside the range


def test_lattice_estimates_are_labelled_and_signed():
    preds = {}
    for pattern in ("dome", "saddle", "expanding"):
        design = parse_design({"schema_version": 1, "lattice": {"pattern": pattern}})
        preds[pattern] = predict_design(design).lattice
    assert preds["dome"].gaussian_sign == 1
    assert preds["saddle"].gaussian_sign == -1
    assert preds["expanding"].gaussian_sign == 0
    # a uniform lattice of independent edges: A/A0 is the square of the edge's ratio
    ((_, edge),) = preds["expanding"].edge_ratios.items()
    assert preds["expanding"].area_ratio.value == pytest.approx(edge.value**2, rel=1e-12)
    line = preds["dome"].line()
    assert "independent-edge estimate" in line and "not the lattice's equilibrium" in line
    record = preds["saddle"].record()
    assert (
        record["method"].startswith("independent-edge estimate") and record["gaussian_sign"] == -1
    )
