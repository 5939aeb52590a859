"""The physical-state verdict: a failed check says no, a missing one says unknown, never yes."""

from __future__ import annotations

import numpy as np

from rotomorph.io.validity import assess, last_physical_step, run_verdict, verdict_record


def test_every_check_passed_is_physical():
    sc = {"converged": np.ones(3), "stable": np.ones(3), "min_clearance": np.full(3, 1.5)}
    v = assess(sc, {}, 3)
    assert [x.verdict for x in v] == ["yes"] * 3 and run_verdict(v).text() == "physical"


def test_missing_checks_are_unknown_not_fine():
    v = assess({}, {}, 2)
    assert {x.verdict for x in v} == {"unknown"}
    assert "stability not checked" in v[0].reasons
    sc = {"converged": np.ones(2), "stable": np.array([1.0, np.nan]), "min_clearance": [2, 2]}
    assert [x.verdict for x in assess(sc, {}, 2)] == ["yes", "unknown"]


def test_failures_are_named_and_win_over_unknowns():
    sc = {
        "converged": np.array([1.0, 1.0, 0.0, 1.0]),
        "stable": np.array([1.0, 0.0, 1.0, np.nan]),
        "min_clearance": np.array([2.0, 2.0, 2.0, 0.01]),
    }
    v = assess(sc, {}, 4)
    assert [x.verdict for x in v] == ["yes", "no", "no", "no"]
    assert v[1].reasons == ("unstable equilibrium",)
    assert v[2].reasons == ("solver did not converge",)
    assert "pass through each other" in v[3].text() and v[3].text().startswith("NOT PHYSICAL")
    assert last_physical_step(v) == 0
    rec = verdict_record(v)
    assert rec["verdict"] == "no" and rec["steps"] == ["yes", "no", "no", "no"]


def test_an_earlier_failure_marks_the_end_of_the_ramp():
    sc = {"converged": np.ones(3), "stable": np.ones(3), "min_clearance": np.array([2, 0.5, 2])}
    end = run_verdict(assess(sc, {}, 3))
    assert end.verdict == "no" and end.reasons[0].startswith("step 1:")


def test_overlap_is_physical_only_with_a_contact_model():
    sc = {"converged": np.ones(1), "stable": np.ones(1), "min_clearance": np.array([0.9])}
    assert assess(sc, {}, 1)[0].verdict == "no"
    assert assess(sc, {"contact": True}, 1)[0].verdict == "yes"
    # with contact modelled, a missing clearance is not a missing check
    assert assess({"converged": [1], "stable": [1]}, {"contact": True}, 1)[0].verdict == "yes"


def test_interpenetrating_stack_layers_are_not_physical_even_with_contact():
    sc = {
        "converged": np.ones(3),
        "stable": np.ones(3),
        "min_clearance": np.full(3, 1.02),
        "stack_overlaps": np.array([0.0, 808.0, np.nan]),
    }
    v = assess(sc, {"contact": True}, 3)
    assert [x.verdict for x in v] == ["yes", "no", "unknown"]
    assert v[1].text() == "NOT PHYSICAL: 808 layer pairs of the printed stack interpenetrate"
    assert "stack admissibility not checked" in v[2].reasons
    assert run_verdict(v).verdict == "no"  # the end inherits the earlier failure
