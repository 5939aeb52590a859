"""Contact benchmark: heating ramps and rods with contact switched on (JSON lines on stdout).

One line per case with ``case``, ``n_nodes``, ``wall_s``, ``newton_iterations``,
``min_clearance_ratio`` (smallest centre-line distance over ``r_a + r_b`` of the pairs allowed
to touch, over every ramp step), ``contacts_active`` (at the end), ``stable`` and, for
lattices, ``area_ratio`` and ``gaussian_sign``:

* ``contracting-5x5``, ``dome-5x5``, ``saddle-5x5``: the paper's 5 x 5 lattices, 16-step ramp
  to full actuation, resting on the bath floor under their buoyant weight (silicone oil);
  ``lift_off_x`` is the actuation at which a node first rises one filament diameter above
  its printed height (null: never), ``final_lift_mm`` the largest rise at the end;
* ``composite-coil``: the composite filament (active fraction 0.5) at ω* = 0.06, heated to
  175 °C with self-contact;
* ``contracting-sinusoid``: the paper's contracting sinusoid with self-contact;
* ``euler-3x``: a perfectly straight clamped column under 3 x its Euler load;
* ``contact-overhead``: wall time of the expanding 5 x 5 ramp with contact on / off.

Run: ``python benchmarks/contact.py [--quick]`` (``--quick``: 4-step ramps).
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np

from rotomorph.contact import Contact
from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.lattice import heat_lattice
from rotomorph.lattice.heating import lattice_gravity
from rotomorph.rod.model import Model
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.static import solve_static


def _emit(row: dict) -> None:
    print(json.dumps(row), flush=True)


def _stable(res) -> bool | None:  # type: ignore[no-untyped-def]
    flags = [s for s in getattr(res, "stable", ())[1:] if s is not None]
    return bool(all(flags)) if flags else None


def lattice_case(pattern: str, steps: int) -> dict:
    lat = sinusoidal_lattice(pattern=pattern)
    t0 = time.perf_counter()
    res = heat_lattice(lat, steps=steps, floor=True, gravity=lattice_gravity(lat))
    wall = time.perf_counter() - t0
    row = {
        "case": f"{pattern}-5x5",
        "n_nodes": int(lat.network.n_nodes),
        "steps": steps,
        "floor": True,
        "buoyant_gravity": True,
        "actuation": res.actuation,
        "wall_s": round(wall, 3),
        "newton_iterations": int(res.total_iterations),
        "min_clearance_ratio": round(float(res.min_clearance.min()), 5),
        "contacts_active": int(res.contacts_active[-1]),
        "stable": _stable(res),
        "area_ratio": round(float(res.area_ratio[-1]), 4),
        "gaussian_sign": int(res.gaussian_sign[-1]),
        "max_halvings": int(res.halvings.max()),
    }
    row["lift_off_x"] = res.first_lift_off()
    row["final_lift_mm"] = round(float(res.floor_lift[-1]), 4)  # type: ignore[index]
    return row


def filament_case(case: str, program, radius: float, steps: int) -> dict:  # type: ignore[no-untyped-def]
    from rotomorph.simulate.filament import simulate_filament

    contact = Contact(radius=radius)
    t0 = time.perf_counter()
    sim = simulate_filament(program, steps=steps, contact=contact)
    wall = time.perf_counter() - t0
    from rotomorph.contact import ContactPotential
    from rotomorph.design.network import Network

    pot = ContactPotential(contact, Network.chain(np.asarray(program.points, float)))
    return {
        "case": case,
        "n_nodes": len(sim.printed),
        "steps": steps,
        "wall_s": round(wall, 3),
        "newton_iterations": int(sim.iterations.sum()),
        "min_clearance_ratio": round(min(pot.clearance(p) for p in sim.positions), 5),
        "contacts_active": int(pot.active_contacts(sim.positions[-1])),
        "stable": None,
        "end_to_end_ratio": round(float(sim.final_ratio), 4),
    }


def euler_case() -> dict:
    n, length, r = 41, 20.0, 0.3
    EI = np.pi * r**4 / 4
    pts = np.stack([np.zeros(n), np.zeros(n), np.linspace(0, length, n)], 1)
    model = Model.chain(
        pts,
        bending_stiffness1=EI,
        bending_stiffness2=EI,
        twist_stiffness=EI / 1.5,
        axial_stiffness=1e3 * EI,
    )
    critical = np.pi**2 * EI / (4 * length**2)  # clamped-free column
    loads = Loads(forces=((n - 1, (0.0, 0.0, -3.0 * critical)),))
    t0 = time.perf_counter()
    res = solve_static(model, Supports.clamp_ends(n), loads, contact=Contact(radius=r))
    wall = time.perf_counter() - t0
    tip = res.positions[-1]
    return {
        "case": "euler-3x",
        "n_nodes": n,
        "wall_s": round(wall, 3),
        "newton_iterations": int(res.iterations),
        "min_clearance_ratio": round(float(res.contact.clearance(res.positions)), 5),
        "contacts_active": int(res.contact.active_contacts(res.positions)),
        "stable": bool(getattr(res, "stable", False)),
        "buckled": bool(np.hypot(tip[0], tip[1]) > 0.01 * length),
        "tip_deflection_mm": round(float(np.hypot(tip[0], tip[1])), 4),
        "tip_height_ratio": round(float(tip[2] / length), 4),
    }


def overhead_case(steps: int) -> dict:
    lat = sinusoidal_lattice(pattern="expanding")
    t0 = time.perf_counter()
    off = heat_lattice(lat, steps=steps)
    t_off = time.perf_counter() - t0
    t0 = time.perf_counter()
    on = heat_lattice(lat, steps=steps, contact=True)
    t_on = time.perf_counter() - t0
    return {
        "case": "contact-overhead",
        "ratio": round(t_on / t_off, 3),
        "wall_off_s": round(t_off, 3),
        "wall_on_s": round(t_on, 3),
        "newton_iterations_off": int(off.total_iterations),
        "newton_iterations_on": int(on.total_iterations),
        "min_clearance_ratio": round(float(on.min_clearance.min()), 5),
        "contacts_active": int(on.contacts_active[-1]),  # type: ignore[index]
    }


def main(quick: bool = False) -> None:
    from rotomorph.io.designfile import Filament
    from rotomorph.simulate.validation import FILAMENT_SPACINGS, sinusoid_filament

    steps = 4 if quick else 16
    heat_lattice(sinusoidal_lattice(n=2, ghost_nodes=2), steps=1, contact=True)  # compile
    _emit(overhead_case(steps))
    for pattern in ("contracting", "dome", "saddle"):
        _emit(lattice_case(pattern, steps))
    coil = Filament(
        speed=3.0,
        rotation_number=0.06,
        radius=0.3,
        active_fraction=0.5,
        spacing=FILAMENT_SPACINGS[0],
        segments=[{"kind": "line", "length": 30.0}],  # type: ignore[list-item]
    ).to_program()
    _emit(filament_case("composite-coil", coil, 0.3, 8))
    sinus = sinusoid_filament("inner", FILAMENT_SPACINGS[0]).to_program()
    _emit(filament_case("contracting-sinusoid", sinus, 0.3, 8))
    _emit(euler_case())


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
