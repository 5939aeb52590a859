"""Contact benchmark: heating ramps and rods with contact switched on (JSON lines on stdout).

One line per case with ``case``, ``n_nodes``, ``wall_s``, ``cpu_s`` (this process's CPU time:
the cost on one core, whatever the load; with ``--repeat k`` the median of k runs, and
``cpu_best_s`` the least), ``newton_iterations``,
``min_clearance_ratio`` (smallest centre-line distance over ``r_a + r_b`` of the pairs allowed
to touch, over every ramp step), ``contacts_active`` (at the end), ``stable``,
``stack_overlaps`` (interpenetrating layer pairs of the printed stack, or of the filament's
one layer, over every step: must be 0), ``contact_distance_ratio`` (median distance over
``r_a + r_b`` of the pairs and floor points carrying force at the end: the contact's thickness
bias) and, for lattices, ``area_ratio`` and ``gaussian_sign``:

* ``contracting-5x5``, ``dome-5x5``, ``saddle-5x5``: the paper's 5 x 5 lattices, 16-step ramp
  to full actuation, resting on the bath floor under their buoyant weight (silicone oil at
  each ramp temperature, as in ``rotomorph paper``);
  ``lift_off_x`` is the actuation at which a node first rises one filament diameter above
  its printed height (null: never), ``final_lift_mm`` the largest rise at the end;
* ``contracting-11x11``, ``contracting-21x21``, ``dome-11x11``, ``dome-21x21``: the same
  lattices at the sizes labs print next (2 321 and 8 841 nodes), 8-step ramps, run only when
  named (a 21 x 21 ramp takes minutes); every lattice line also gives ``energy_nmm`` (the end
  state's total energy, to compare end states) and ``s_per_iteration`` (CPU time per Newton
  iteration, whose growth with ``n_nodes`` is the per-iteration cost's scaling); where one run
  measures a pattern at two sizes or more, a ``<pattern>-iteration-scaling`` line gives
  ``n_nodes`` and ``per_iteration_s`` per size and the ``exponent`` fitted to
  ``per_iteration_s ~ n_nodes^exponent`` (least squares in log-log);
* ``composite-coil``: the composite filament (active fraction 0.5) at ω* = 0.06, heated to
  175 °C with self-contact;
* ``contracting-sinusoid``: the paper's contracting sinusoid with self-contact;
* ``euler-3x``: the perfectly straight clamped-free column of ``EulerColumnCase`` under
  3 x its Euler load, with its elastica tip;
* ``contact-overhead``: wall (and CPU) time of the expanding 5 x 5 ramp with contact on / off,
  best of two alternating runs each after a warm-up run.

Run: ``python benchmarks/contact.py [--quick] [--repeat K] [CASE ...]`` (``--quick``: 4-step
ramps; cases by name, default all but the large lattices; e.g. ``contracting-5x5
contracting-11x11 contracting-21x21`` for the contracting lattice's scaling line). The
lattices present their printed stack to contact (one capsule per layer, three layers).
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np

from rotomorph.contact import Contact
from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.lattice import heat_lattice
from rotomorph.lattice.heating import lattice_buoyancy
from rotomorph.rod.cases import EulerColumnCase
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.static import solve_static


def _emit(row: dict) -> None:
    print(json.dumps(row), flush=True)


def _stable(res) -> bool | None:  # type: ignore[no-untyped-def]
    flags = [s for s in getattr(res, "stable", ())[1:] if s is not None]
    return bool(all(flags)) if flags else None


def _contact_ratio(pot, where) -> float | None:  # type: ignore[no-untyped-def]
    """Median ``d / (r_a + r_b)`` of the pairs (and floor points) carrying force at ``where``
    (``contact_ratios``: inside the barrier's zone, which ends at touching), null when none
    does."""
    ratios = pot.contact_ratios(where)
    return round(float(np.median(ratios)), 5) if len(ratios) else None


def _overlaps(pot, where) -> int:  # type: ignore[no-untyped-def]
    """Allowed pairs of a one-layer filament closer than ``r_a + r_b`` less the contact's
    offset: the admissibility check's count (``rotomorph.lattice.admissibility``), for which a
    pressed contact may settle inside touching by less than the offset."""
    d, touching = pot.distances(where)
    return int(np.count_nonzero(d < touching - pot.offset))


def _bound(res):  # type: ignore[no-untyped-def]
    """The ramp's contact settings bound to its lattice (distances only: any stiffness)."""
    from rotomorph.contact.stacked import StackedContact

    net = res.lattice.network
    up = np.tile([0.0, 0.0, 1.0], (net.n_edges, 1))  # the lattice's printed directors
    if res.contact.stack.is_single:
        from rotomorph.contact import ContactPotential

        return ContactPotential(res.contact, net)
    return StackedContact(res.contact, net, up)


#: the large lattices (branch nodes per side), run only when named; 8-step ramps
LARGE = (11, 21)
LARGE_STEPS = 8


def lattice_case(pattern: str, steps: int, repeat: int = 1, n: int = 5) -> dict:
    lat = sinusoidal_lattice(n=n, pattern=pattern)
    cpus, walls = [], []
    for _ in range(repeat):
        c0, t0 = time.process_time(), time.perf_counter()
        res = heat_lattice(lat, steps=steps, floor=True, gravity=lattice_buoyancy(lat))
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    wall, cpu = float(np.median(walls)), float(np.median(cpus))
    row = {
        "case": f"{pattern}-{n}x{n}",
        "n_nodes": int(lat.network.n_nodes),
        "steps": steps,
        "floor": True,
        "buoyant_gravity": True,
        "actuation": res.actuation,
        "wall_s": round(wall, 3),
        "cpu_s": round(cpu, 3),
        "cpu_best_s": round(min(cpus), 3),
        "repeats": repeat,
        "layers": int(lat.layers),
        "newton_iterations": int(res.total_iterations),
        "min_clearance_ratio": round(float(res.min_clearance.min()), 5),
        "contacts_active": int(res.contacts_active[-1]),
        "stable": _stable(res),
        "stack_overlaps": int(np.max(res.stack_overlaps)),  # type: ignore[arg-type]
        "contact_distance_ratio": _contact_ratio(_bound(res), res.states[-1]),
        "area_ratio": round(float(res.area_ratio[-1]), 4),
        "gaussian_sign": int(res.gaussian_sign[-1]),
        "energy_nmm": float(res.energy[-1]),
        "max_halvings": int(res.halvings.max()),
        "s_per_iteration": round(cpu / max(int(res.total_iterations), 1), 5),
    }
    row["lift_off_x"] = res.first_lift_off()
    row["final_lift_mm"] = round(float(res.floor_lift[-1]), 4)  # type: ignore[index]
    return row


def scaling_row(pattern: str, rows: list[dict]) -> dict | None:
    """The per-iteration cost's exponent in the lattice size over ``rows`` of one pattern."""
    if len(rows) < 2:
        return None
    nodes = np.array([r["n_nodes"] for r in rows], dtype=float)
    per = np.array([r["cpu_s"] / max(r["newton_iterations"], 1) for r in rows])
    return {
        "case": f"{pattern}-iteration-scaling",
        "sizes": [r["case"] for r in rows],
        "n_nodes": [int(n) for n in nodes],
        "newton_iterations": [r["newton_iterations"] for r in rows],
        "per_iteration_s": [round(float(p), 6) for p in per],
        "exponent": round(float(np.polyfit(np.log(nodes), np.log(per), 1)[0]), 3),
    }


def filament_case(case: str, program, radius: float, steps: int) -> dict:  # type: ignore[no-untyped-def]
    from rotomorph.simulate.filament import simulate_filament

    contact = Contact(radius=radius)
    c0, t0 = time.process_time(), time.perf_counter()
    sim = simulate_filament(program, steps=steps, contact=contact)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    from rotomorph.contact import ContactPotential
    from rotomorph.design.network import Network

    pot = ContactPotential(contact, Network.chain(np.asarray(program.points, float)))
    overlaps = max(_overlaps(pot, p) for p in sim.positions)  # one layer
    return {
        "case": case,
        "n_nodes": len(sim.printed),
        "steps": steps,
        "wall_s": round(wall, 3),
        "cpu_s": round(cpu, 3),
        "newton_iterations": int(sim.iterations.sum()),
        "min_clearance_ratio": round(min(pot.clearance(p) for p in sim.positions), 5),
        "contacts_active": int(pot.active_contacts(sim.positions[-1])),
        "stable": _stable(sim),
        "stack_overlaps": overlaps,
        "contact_distance_ratio": _contact_ratio(pot, sim.positions[-1]),
        "end_to_end_ratio": round(float(sim.final_ratio), 4),
    }


def euler_case() -> dict:
    """The clamped-free column of :class:`~rotomorph.rod.cases.EulerColumnCase` (first edge
    clamped, centred on the origin, so the free length is exact), started exactly straight at
    3 x its Euler load, with self-contact; compared with the elastica's tip."""
    case, n, ratio = EulerColumnCase(), 41, 3.0
    loads = Loads(forces=((n - 1, (-ratio * case.euler_load, 0.0, 0.0)),))
    c0, t0 = time.process_time(), time.perf_counter()
    res = solve_static(
        case.model(n), Supports.clamp_ends(n), loads, contact=Contact(radius=case.radius)
    )
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    tip = res.positions[-1]
    x_ref, y_ref = case.elastica_tip(ratio)
    return {
        "case": "euler-3x",
        "n_nodes": n,
        "wall_s": round(wall, 3),
        "cpu_s": round(cpu, 3),
        "newton_iterations": int(res.iterations),
        "min_clearance_ratio": round(float(res.contact.clearance(res.positions)), 5),
        "contacts_active": int(res.contact.active_contacts(res.positions)),
        "stable": bool(res.stable),
        "stack_overlaps": _overlaps(res.contact, res.positions),
        "contact_distance_ratio": _contact_ratio(res.contact, res.positions),
        "buckled": bool(np.hypot(tip[1], tip[2]) > 0.01 * case.length),
        "tip_lateral_ratio": round(float(np.hypot(tip[1], tip[2]) / case.length), 4),
        "tip_lateral_elastica": round(y_ref, 4),
        "tip_axial_ratio": round(float(tip[0] / case.length), 4),
        "tip_axial_elastica": round(x_ref, 4),
    }


def overhead_case(steps: int, repeats: int = 2) -> dict:
    """Expanding 5 x 5 ramp with contact on / off (where nothing touches): the best of
    ``repeats`` alternating runs of each, after one untimed run of each (the first ramp in a
    process pays for caches that the later ones reuse)."""
    lat = sinusoidal_lattice(pattern="expanding")
    best: dict[bool, tuple[float, float]] = {}
    runs = {}
    for k in range(repeats + 1):
        for contact in (False, True):
            c0, t0 = time.process_time(), time.perf_counter()
            runs[contact] = heat_lattice(lat, steps=steps, contact=contact)
            cpu, wall = time.process_time() - c0, time.perf_counter() - t0
            if k:
                old = best.get(contact, (np.inf, np.inf))
                best[contact] = (min(old[0], wall), min(old[1], cpu))
    off, on = runs[False], runs[True]
    (t_off, c_off), (t_on, c_on) = best[False], best[True]
    return {
        "case": "contact-overhead",
        "ratio": round(t_on / t_off, 3),
        "cpu_ratio": round(c_on / c_off, 3),
        "wall_off_s": round(t_off, 3),
        "wall_on_s": round(t_on, 3),
        "cpu_off_s": round(c_off, 3),
        "cpu_on_s": round(c_on, 3),
        "newton_iterations_off": int(off.total_iterations),
        "newton_iterations_on": int(on.total_iterations),
        "min_clearance_ratio": round(float(on.min_clearance.min()), 5),
        "contacts_active": int(on.contacts_active[-1]),  # type: ignore[index]
        "stack_overlaps": int(np.max(on.stack_overlaps)),  # type: ignore[arg-type]
        "contact_distance_ratio": _contact_ratio(_bound(on), on.states[-1]),
    }


def main(quick: bool = False, only: tuple[str, ...] = (), repeat: int = 1) -> None:
    from rotomorph.io.designfile import Filament
    from rotomorph.simulate.validation import FILAMENT_SPACINGS, sinusoid_filament

    def wanted(case: str) -> bool:
        return not only or case in only

    steps = 4 if quick else 16
    heat_lattice(sinusoidal_lattice(n=2, ghost_nodes=2), steps=1, contact=True)  # compile
    # ... and the floor, buoyancy and printed-stack paths the lattice cases take, so that the
    # first lattice timed does not pay for their compilation
    small = sinusoidal_lattice(n=2, ghost_nodes=2, pattern="contracting")
    heat_lattice(small, steps=1, floor=True, gravity=lattice_buoyancy(small))
    if wanted("contact-overhead"):
        _emit(overhead_case(steps))
    lattices: dict[str, list[dict]] = {}
    for pattern in ("contracting", "dome", "saddle"):
        if wanted(f"{pattern}-5x5"):
            row = lattice_case(pattern, steps, repeat)
            lattices.setdefault(pattern, []).append(row)
            _emit(row)
    for n in LARGE:
        for pattern in ("contracting", "dome"):
            if f"{pattern}-{n}x{n}" in only:
                row = lattice_case(pattern, 4 if quick else LARGE_STEPS, repeat, n)
                lattices.setdefault(pattern, []).append(row)
                _emit(row)
    for pattern, rows in lattices.items():
        scaling = scaling_row(pattern, rows)
        if scaling is not None:
            _emit(scaling)
    if wanted("composite-coil"):
        coil = Filament(
            speed=3.0,
            rotation_number=0.06,
            radius=0.3,
            active_fraction=0.5,
            spacing=FILAMENT_SPACINGS[0],
            segments=[{"kind": "line", "length": 30.0}],  # type: ignore[list-item]
        ).to_program()
        _emit(filament_case("composite-coil", coil, 0.3, 8))
    if wanted("contracting-sinusoid"):
        sinus = sinusoid_filament("inner", FILAMENT_SPACINGS[0]).to_program()
        _emit(filament_case("contracting-sinusoid", sinus, 0.3, 8))
    if wanted("euler-3x"):
        _emit(euler_case())


if __name__ == "__main__":
    args = sys.argv[1:]
    k = int(args[args.index("--repeat") + 1]) if "--repeat" in args else 1
    names = [a for i, a in enumerate(args) if not a.startswith("--") and args[i - 1] != "--repeat"]
    main(quick="--quick" in args, only=tuple(names), repeat=k)
