"""Fig. 5: a lattice filter and a lattice gripper
==============================================

The paper's two applications of active–passive lattices (its Fig. 5), computed:

**Filter.** An expanding lattice catches spheres when cold and lets them through when hot. A
sphere of diameter ``D`` passes a unit cell when a circle of diameter ``D`` fits between the
filament surfaces of the cell (:func:`rotomorph.analysis.aperture.passing_diameters`). The
example follows the opening of every cell over a heating ramp (25 → 175 °C, every printed line
driven by its print program through the materials chain) and says, for each sphere diameter,
from which temperature it passes. The paper's objects are 5 mm spheres.

**Gripper.** A contracting lattice closes on rods standing in its cells when hot and releases
them when cooled (the paper heats to 175 °C and cools to 50 °C; acrylic rods 3.5 mm in diameter,
6 mm long). The rods are rigid cylinders through the centres of the cells around the lattice's
centre; filaments touch them and each other through the contact barrier (never pass through).
The example reports the force each rod receives at every temperature.

Assumptions (the paper gives no lattice dimensions): the package's sinusoidal lattice with
A/l = 0.25, filament radius 0.3 mm, three layers; node spacing l = 5 mm for the filter (the
package default) and l = 7 mm for the gripper, the smallest round value for which the printed
cells admit 3.5 mm rods (the example prints the exact minimum); the lattice is held by its
centre node (the paper mounts it on a frame or handle); quasi-static, no gravity, frictionless.

Run: ``python examples/fig5_filter_gripper.py [--full] [--figure PATH]``. Prints one JSON object
per line. The default is a small 3 × 3 lattice (a quick check); ``--full`` is the paper's 5 × 5.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from rotomorph.analysis.aperture import passing_diameters
from rotomorph.contact import Contact, ContactPotential, Cylinder
from rotomorph.contact.stack import Stack
from rotomorph.contact.stacked import StackedContact
from rotomorph.design.lattices import Lattice, sinusoidal_lattice
from rotomorph.lattice.actuation import default_stiffness, get_actuation
from rotomorph.lattice.admissibility import admissibility, lattice_stack
from rotomorph.lattice.heating import RAMP_OPTIONS, heat_lattice
from rotomorph.lattice.model import lattice_model
from rotomorph.solve.continuation import continuation
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.static import StaticResult, solve_static

SPHERE_DIAMETERS = (3.0, 4.0, 5.0, 6.0)  # mm; the paper's spheres are 5 mm
ROD_DIAMETER, ROD_LENGTH = 3.5, 6.0  # mm, the paper's acrylic rods
FILTER_SPACING, GRIPPER_SPACING = 5.0, 7.0  # mm (assumed, see the module docstring)
HOT, RELEASE = 175.0, 50.0  # °C, the paper's heating and release temperatures


def centre_support(lattice: Lattice) -> Supports:
    """The lattice held at its central branch node (the frame or handle)."""
    c = lattice.n // 2
    return Supports(pinned_nodes=(lattice.branch_index(c, c),))


def filter_study(n: int, ghost_nodes: int, steps: int) -> tuple[list[dict], dict]:
    """Opening of every cell of an expanding lattice over 25 → 175 °C; sphere verdicts."""
    lattice = sinusoidal_lattice(
        n=n, ghost_nodes=ghost_nodes, spacing=FILTER_SPACING, amplitude=0.25 * FILTER_SPACING
    )
    ramp = heat_lattice(lattice, actuation="program", steps=steps, supports="pinned-centre")
    openings = np.array(
        [passing_diameters(p, lattice.edge_chains, n, lattice.radius) for p in ramp.positions]
    )
    rows = [
        {
            "study": "filter",
            "temperature_C": float(t),
            "opening_min_mm": float(d.min()),
            "opening_max_mm": float(d.max()),
            "area_ratio": float(a),
            "stable": bool(s),
            "admissible": bool(ok),  # no two layers of the printed stacks interpenetrate
        }
        for t, d, a, s, ok in zip(
            ramp.parameter, openings, ramp.area_ratio, ramp.stable, ramp.admissible, strict=True
        )
    ]
    verdict: dict = {"study": "filter_spheres", "spacing_mm": FILTER_SPACING, "n": n}
    for size in SPHERE_DIAMETERS:
        passing = np.flatnonzero(openings.min(axis=1) > size)  # through every cell
        if not len(passing):
            verdict[f"sphere_{size:g}mm"] = "caught at every temperature"
        elif passing[0] == 0:
            verdict[f"sphere_{size:g}mm"] = "passes already when printed (25 °C)"
        else:
            t_pass = float(ramp.parameter[passing[0]])
            verdict[f"sphere_{size:g}mm"] = f"caught below, passes from {t_pass:.0f} °C"
            verdict[f"sphere_{size:g}mm_pass_temperature_C"] = t_pass
    return rows, verdict


def rod_centres(lattice: Lattice) -> np.ndarray:
    """Centres ``(4, 3)`` of the four cells around the central node (mm)."""
    n, c, x = lattice.n, lattice.n // 2, lattice.network.nodes
    out = []
    for i in (c - 1, c):
        for j in (c - 1, c):
            k = n * i + j
            out.append(x[[k, k + n, k + n + 1, k + 1]].mean(axis=0))
    return np.array(out)


def rod_forces(
    result: StaticResult, rods: tuple[Cylinder, ...], radius: float, stack: Stack
) -> np.ndarray:
    """In-plane force on each rod ``(R,)`` (N): the reaction of the barrier of the filaments'
    printed layers (``stack``)."""
    bound = result.contact
    assert bound is not None
    out = []
    for rod in rods:
        settings = Contact(
            radius=radius,
            obstacles=(rod,),
            self_contact=False,
            stiffness=bound.kappa,
            activation_distance=bound.dhat,
            stack=stack,
        )
        if stack.is_single:
            single: ContactPotential | StackedContact = ContactPotential(settings, bound.network)
            force = -single.forces(result.positions).sum(axis=0)  # on the rod
        else:
            up = np.tile([0.0, 0.0, 1.0], (bound.network.n_edges, 1))  # printed directors
            single = StackedContact(settings, bound.network, up)
            force = -single.forces(result.state).sum(axis=0)
        out.append(float(np.hypot(force[0], force[1])))
    return np.array(out)


def gripper_study(n: int, ghost_nodes: int, heat_steps: int, cool_steps: int) -> list[dict]:
    """A contracting lattice heated onto four rods, then cooled to release them."""
    lattice = sinusoidal_lattice(
        n=n,
        ghost_nodes=ghost_nodes,
        spacing=GRIPPER_SPACING,
        amplitude=0.25 * GRIPPER_SPACING,
        pattern="contracting",
    )
    program = get_actuation("program")
    stiffness, materials = default_stiffness(program)
    model = lattice_model(lattice, stiffness=stiffness, filament_model=materials)
    supports = centre_support(lattice)
    rods = tuple(
        Cylinder.along((x, y, 0.0), (0.0, 0.0, 1.0), ROD_DIAMETER / 2, ROD_LENGTH)
        for x, y, _ in rod_centres(lattice)
    )
    stack = lattice_stack(lattice)  # every edge presents its printed layers to the rods
    contact = Contact(radius=lattice.radius, obstacles=rods, stack=stack)

    def solve(temperature: float, state):  # type: ignore[no-untyped-def]
        return solve_static(
            program.natural(model, temperature),
            supports,
            Loads(),
            initial=state,
            options=RAMP_OPTIONS,
            contact=contact,
        )

    heating = np.linspace(program.start, HOT, heat_steps + 1)[1:]
    cooling = np.linspace(HOT, RELEASE, cool_steps + 1)[1:]
    up = continuation(solve, heating, model.model.reference_state(), start=program.start)
    down = continuation(solve, cooling, up.final.state, start=HOT)
    rows = []
    printed = passing_diameters(lattice.network.nodes, lattice.edge_chains, n, lattice.radius)
    rows.append(
        {
            "study": "gripper",
            "temperature_C": program.start,
            "phase": "printed",
            "rod_forces_N": [0.0] * len(rods),
            "opening_min_mm": float(printed.min()),
            "clearance": None,
            "stable": True,
            "admissible": True,
        }
    )
    for phase, path in (("heating", up), ("cooling", down)):
        for step in path.steps:
            res = step.result
            openings = passing_diameters(res.positions, lattice.edge_chains, n, lattice.radius)
            rows.append(
                {
                    "study": "gripper",
                    "temperature_C": float(step.parameter),
                    "phase": phase,
                    "rod_forces_N": rod_forces(res, rods, lattice.radius, stack).tolist(),
                    "opening_min_mm": float(openings.min()),
                    "clearance": res.contact.clearance(res.state),  # type: ignore[union-attr]
                    "stable": bool(res.stable),
                    # no two layers of the printed stacks pass through each other
                    "admissible": admissibility(lattice, res.state, contact=contact).admissible,
                }
            )
    return rows


def minimum_gripper_spacing() -> float:
    """Smallest spacing l (mm) whose printed cells admit the rods (A/l = 0.25, r = 0.3 mm).

    The printed centre-line cell scales with l, so its opening is ``c l - 2 r``.
    """
    unit = sinusoidal_lattice(n=2, spacing=1.0, amplitude=0.25, pattern="contracting")
    c = float(passing_diameters(unit.network.nodes, unit.edge_chains, 2, 0.0)[0])
    return (ROD_DIAMETER + 2 * unit.radius) / c


def figure(filter_rows: list[dict], gripper_rows: list[dict], path: Path) -> None:
    """Opening vs temperature (filter) and rod force vs temperature (gripper)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from rotomorph.io.atomic import atomic_path

    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    t = [r["temperature_C"] for r in filter_rows]
    a.plot(t, [r["opening_min_mm"] for r in filter_rows], "o-", label="cell opening")
    a.axhline(5.0, color="k", ls="--", lw=1, label="5 mm sphere")
    a.set(xlabel="temperature (°C)", ylabel="largest passing sphere (mm)")
    a.set_title(f"Filter: expanding lattice, l = {FILTER_SPACING:g} mm", fontsize=10)
    a.legend()
    hot = [r for r in gripper_rows if r["phase"] == "heating"][-1:]
    for phase, style in (("heating", "o-"), ("cooling", "s--")):
        rows = [r for r in gripper_rows if r["phase"] in (phase, "printed")]
        if phase == "cooling":  # from the hot state down
            rows = hot + [r for r in gripper_rows if r["phase"] == "cooling"]
        forces = np.array([r["rod_forces_N"] for r in rows]) * 1e3
        b.plot([r["temperature_C"] for r in rows], forces.mean(axis=1), style, label=phase)
    b.set(xlabel="temperature (°C)", ylabel="mean force on a rod (mN)")
    b.set_title(
        f"Gripper: contracting lattice on 3.5 mm rods, l = {GRIPPER_SPACING:g} mm", fontsize=10
    )
    b.legend()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=120, format=path.suffix.lstrip(".") or "png")
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--full", action="store_true", help="the paper's 5 x 5 lattices")
    parser.add_argument("--figure", type=Path, help="write the figure (PNG) here")
    args = parser.parse_args(argv)
    n, ghost, heat, cool = (5, 10, 16, 5) if args.full else (3, 4, 4, 2)
    filter_rows, verdict = filter_study(n, ghost, heat)
    gripper_rows = gripper_study(n, ghost, heat, cool)
    for row in [*filter_rows, verdict, *gripper_rows]:
        print(json.dumps(row))
    print(
        json.dumps({"study": "gripper_geometry", "minimum_spacing_mm": minimum_gripper_spacing()})
    )
    if args.figure is not None:
        figure(filter_rows, gripper_rows, args.figure)
    return 0


if __name__ == "__main__":
    main()  # always 0; not SystemExit, which would end a documentation build running it
