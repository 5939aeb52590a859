"""What a run's files hold beyond positions: Janus sides, twist, the printed geometry, checks.

:func:`describe_run` turns a :class:`~rotomorph.simulate.design.DesignSimulation` into the
:class:`~rotomorph.io.results.RunResults` that is written, adding

- per step: the material directors ``directors`` (m1, ``(S, E, 3)``), the interface normal
  toward the active half ``active_normal`` (``(S, E, 3)``), the material twist per vertex
  ``twist`` (``(S, N)``, 1/mm, NaN at chain ends and branch nodes) and the checks of
  :mod:`rotomorph.io.validity` (``converged``, ``stable``, ``min_clearance``);
- static arrays: ``arc_length`` per node (mm, printed, from each chain's start),
  ``filament_id`` per node and segment (chain index; for lattices the lattice edge),
  ``radius`` (mm), ``interface_angle`` (rad, printed, from the design's reference director),
  ``active_fraction`` per segment and, for lattices, ``lattice_edge`` per segment;
- the print programs (what the G-code is written from) and the physical-state verdict.

The active side of a segment is fixed in its material frame: with β the angle of the printed
interface normal n₀ from m1 toward m2 in the printed state, the deformed normal is
n = cos β m1 + sin β m2.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray, IntArray
from rotomorph.geometry import pair_strains
from rotomorph.io.results import RunResults, program_record, to_jsonable
from rotomorph.io.validity import assess, verdict_record
from rotomorph.simulate.extrapolation import run_extrapolation

__all__ = [
    "active_normals",
    "chain_clearance",
    "chain_segments",
    "chains_segments",
    "describe_run",
    "material_twist",
]


def chain_segments(edges: IntArray, chain: IntArray) -> IntArray:
    """Segment index of each consecutive node pair of ``chain`` (−1 where none exists)."""
    return chains_segments(edges, [chain])[0]


def chains_segments(edges: IntArray, chains: Sequence[IntArray]) -> list[IntArray]:
    """:func:`chain_segments` of many chains at once (one sorted lookup, not one per chain)."""
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    chains = [np.asarray(c, dtype=np.int64).reshape(-1) for c in chains]
    size = 1 + max([int(edges.max(initial=0))] + [int(c.max(initial=0)) for c in chains])
    key = np.sort(edges, axis=1) @ np.array([size, 1])
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    a = np.concatenate([c[:-1] for c in chains] + [np.zeros(0, dtype=np.int64)])
    b = np.concatenate([c[1:] for c in chains] + [np.zeros(0, dtype=np.int64)])
    query = np.minimum(a, b) * size + np.maximum(a, b)
    pos = np.searchsorted(sorted_key, query, side="right") - 1  # the last such segment
    hit = pos >= 0
    hit[hit] = sorted_key[pos[hit]] == query[hit]
    seg = np.where(hit, order[np.maximum(pos, 0)], -1)
    return np.split(seg, np.cumsum([max(len(c) - 1, 0) for c in chains])[:-1])


def active_normals(states: tuple[Any, ...], printed_normals: FloatArray) -> tuple[FloatArray, ...]:
    """Material directors m1 and interface normals toward the active half per state.

    Parameters
    ----------
    states
        Rod states, the first the printed reference state.
    printed_normals
        Interface normals n₀ toward the active half per segment ``(E, 3)`` in the printed state.

    Returns
    -------
    directors, normals
        ``(S, E, 3)`` each.
    """
    m1_0, m2_0 = states[0].material_directors()
    beta = np.arctan2(
        np.einsum("ij,ij->i", printed_normals, m2_0), np.einsum("ij,ij->i", printed_normals, m1_0)
    )
    c, s = np.cos(beta)[:, None], np.sin(beta)[:, None]
    m1s, ns = [], []
    for st in states:
        m1, m2 = st.material_directors()
        m1s.append(m1)
        ns.append(c * m1 + s * m2)
    return np.stack(m1s), np.stack(ns)


def material_twist(
    positions: FloatArray, directors: FloatArray, edges: IntArray, chains: list[IntArray]
) -> FloatArray:
    """Material twist per node ``(S, N)`` (1/mm) along ``chains``; NaN at chain ends."""
    out = np.full(positions.shape[:2], np.nan)
    kept = [
        (np.asarray(chain), seg)
        for chain, seg in zip(chains, chains_segments(edges, chains), strict=True)
        if len(chain) >= 3 and not (seg < 0).any()
    ]
    if not kept:
        return out
    # every interior vertex of every chain at once (row-wise the same operations as
    # polyline_strains on each chain)
    prev, mid, nxt = (np.concatenate([c[a : len(c) - 2 + a] for c, _ in kept]) for a in range(3))
    seg_e = np.concatenate([s[:-1] for _, s in kept])
    seg_f = np.concatenate([s[1:] for _, s in kept])
    for k in range(len(positions)):
        x, d = positions[k], directors[k]
        e, f = x[mid] - x[prev], x[nxt] - x[mid]
        _, _, tw = pair_strains(e, f, d[seg_e], d[seg_f])
        vor = 0.5 * (np.linalg.norm(e, axis=-1) + np.linalg.norm(f, axis=-1))
        out[k, mid] = tw / vor
    return out


def chain_clearance(positions: FloatArray, diameter: float) -> FloatArray:
    """Smallest distance between the segments of one filament per step, in diameters ``(S,)``.

    Pairs closer along the filament than π·d (printed arc length) are skipped: a tube of
    diameter d cannot bend back onto itself over a shorter length, so their distance says
    nothing about overlap (a filament that contracts brings them closer without any overlap).
    Above 2 diameters the value is capped at 2.
    """
    from rotomorph.lattice.heating import segment_clearance

    p0 = np.asarray(positions[0], dtype=float)
    n = len(p0)
    if n < 3:
        return np.full(len(positions), 2.0)
    edges = np.stack([np.arange(n - 1), np.arange(1, n)], axis=1)
    arc = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p0, axis=0), axis=1))]
    mid = 0.5 * (arc[:-1] + arc[1:])
    stop = np.searchsorted(mid, mid + np.pi * diameter, side="left")  # first j too far
    count = stop - np.arange(n - 1) - 1
    i = np.repeat(np.arange(n - 1), count)
    j = i + 1 + (np.arange(len(i)) - np.repeat(np.cumsum(count) - count, count))
    skip = np.stack([i, j], axis=1)
    return np.array(
        [segment_clearance(p, edges, diameter, ignore=skip) for p in np.asarray(positions)]
    )


def _combine(flags: FloatArray) -> FloatArray:
    """Per step over filaments ``(F, S)``: the smallest value; NaN (unknown) if any filament is
    unknown and no known value fails (is below 1)."""
    if flags.size == 0:
        return np.full(flags.shape[1:], np.nan)
    with np.errstate(all="ignore"):
        low = np.nanmin(np.where(np.isnan(flags), np.inf, flags), axis=0)
    unknown = np.isnan(flags).any(axis=0)
    return np.where(unknown & (low >= 1.0), np.nan, np.where(np.isinf(low), np.nan, low))


def _filament_extras(sim: Any, n: int, e: int) -> tuple[dict, dict, dict, list, list]:
    chains_meta = sim.metadata.get("chains", [])
    static: dict[str, Any] = {
        "arc_length": np.zeros(n),
        "filament_id": np.zeros(n, dtype=np.int64),
        "segment_filament_id": np.zeros(e, dtype=np.int64),
        "radius": np.zeros(e),
        "interface_angle": np.full(e, np.nan),
        "active_fraction": np.zeros(e),
    }
    programs, chains = [], []
    directors = np.full((sim.positions.shape[0], e, 3), np.nan)
    normals = np.full_like(directors, np.nan)
    clearance = np.full((len(sim.filaments), sim.positions.shape[0]), np.nan)
    stable = np.full_like(clearance, np.nan)
    edge_offset = 0
    for i, fil in enumerate(sim.filaments):
        start, stop = int(chains_meta[i]["start"]), int(chains_meta[i]["stop"])
        nodes = np.arange(start, stop)
        segs = np.arange(edge_offset, edge_offset + len(nodes) - 1)
        edge_offset += len(nodes) - 1
        chains.append(nodes)
        program = getattr(fil, "program", None)
        static["filament_id"][nodes] = i
        static["segment_filament_id"][segs] = i
        static["arc_length"][nodes] = np.r_[
            0.0, np.cumsum(np.linalg.norm(np.diff(fil.printed, axis=0), axis=1))
        ]
        if fil.stable:
            stable[i] = [np.nan if f is None else float(f) for f in fil.stable]
        if program is None:
            continue
        programs.append(program_record(program, fil.name))
        static["radius"][segs] = program.radius
        static["active_fraction"][segs] = program.active_fraction
        static["interface_angle"][segs] = program.interface_angle
        if fil.states:
            m1, nn = active_normals(fil.states, program.interface_normals)
            directors[:, segs], normals[:, segs] = m1, nn
        clearance[i] = chain_clearance(fil.positions, 2.0 * program.radius)
    scalars = {"stable": _combine(stable), "min_clearance": _combine(clearance)}
    strains = [np.asarray(getattr(f, "max_axial_strain", ()), dtype=float) for f in sim.filaments]
    if strains and all(len(v) == sim.positions.shape[0] for v in strains):
        scalars["max_axial_strain"] = np.max(np.stack(strains), axis=0)
    eig = [np.asarray(getattr(f, "lowest_eigenvalue", ()), dtype=float) for f in sim.filaments]
    if eig and all(len(v) == sim.positions.shape[0] for v in eig):
        with np.errstate(all="ignore"):
            scalars["lowest_eigenvalue"] = np.min(np.stack(eig), axis=0)
    fields = {"directors": directors, "active_normal": normals}
    per_filament = []
    for i, (c, st) in enumerate(zip(clearance, stable, strict=True)):
        flags = {"converged": np.ones(len(c)), "stable": st, "min_clearance": c}
        if len(strains[i]) == len(c):
            flags["max_axial_strain"] = strains[i]
        per_filament.append(
            {
                "min_clearance_diameters": float(c[-1]) if np.isfinite(c[-1]) else None,
                "physical": verdict_record(assess(flags, {}, len(c))),
            }
        )
    return static, fields, scalars, programs, [chains, per_filament]


def _lattice_extras(sim: Any, n: int, e: int) -> tuple[dict, dict, dict, list, list]:
    from rotomorph.lattice.model import interface_normals

    res = sim.lattice
    lattice = res.lattice
    edges = np.asarray(sim.edges)
    chains = [np.asarray(c) for c in lattice.edge_chains]
    lattice_edge = np.full(e, -1, dtype=np.int64)
    arc = np.full(n, np.nan)
    node_edge = np.full(n, -1, dtype=np.int64)
    printed = np.asarray(sim.positions[0])
    for j, (chain, seg) in enumerate(zip(chains, chains_segments(edges, chains), strict=True)):
        lattice_edge[seg[seg >= 0]] = j
        inner = chain[1:-1]
        node_edge[inner] = j
        arc[chain] = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(printed[chain], axis=0), axis=1))]
    static = {
        "arc_length": arc,
        "filament_id": node_edge,
        "lattice_edge": lattice_edge,
        "radius": np.full(e, float(lattice.radius)),
        "interface_angle": np.asarray(lattice.interface_angle, dtype=float),
        "active_fraction": np.full(e, float(lattice.active_fraction)),
    }
    fields: dict[str, Any] = {}
    if res.states:
        m1, nn = active_normals(res.states, interface_normals(lattice))
        fields = {"directors": m1, "active_normal": nn}
    stable = (
        np.array([np.nan if f is None else float(f) for f in res.stable])
        if res.stable
        else (np.full(sim.positions.shape[0], np.nan))
    )
    programs = [program_record(p, f"layer {p.layer}") for p in lattice.print_programs()]
    scalars = {"stable": stable}
    strain = np.asarray(getattr(res, "max_axial_strain", ()), dtype=float)
    if len(strain) == sim.positions.shape[0]:
        scalars["max_axial_strain"] = strain
    eig = np.asarray(getattr(res, "lowest_eigenvalue", ()), dtype=float)
    if len(eig) == sim.positions.shape[0]:
        scalars["lowest_eigenvalue"] = eig
    return static, fields, scalars, programs, [chains, []]


def describe_run(sim: Any) -> RunResults:
    """The self-describing :class:`RunResults` of a design simulation (module docstring)."""
    base = sim.run_results()
    n, e = base.positions.shape[1], len(base.edges)
    if sim.kind == "lattice" and sim.lattice is not None:
        static, fields, scalars, programs, (chains, per_fil) = _lattice_extras(sim, n, e)
    else:
        static, fields, scalars, programs, (chains, per_fil) = _filament_extras(sim, n, e)
    if "directors" in fields:
        fields["twist"] = material_twist(base.positions, fields["directors"], base.edges, chains)
    s = base.n_steps
    all_scalars = dict(base.scalars)
    # every stored step comes from a converged solve (a failed one raises) or is the printed state
    all_scalars.setdefault("converged", np.ones(s))
    for k, v in scalars.items():
        all_scalars.setdefault(k, np.asarray(v, dtype=float))
    meta = dict(base.metadata)
    meta.setdefault("contact", False)
    verdicts = assess(all_scalars, meta, s)
    meta["physical"] = verdict_record(verdicts)
    reasons, per_filament = run_extrapolation(sim)
    meta["extrapolated"] = bool(reasons)
    meta["extrapolation"] = reasons
    if per_filament:
        per_fil = [
            {**extra, "extrapolation": why}
            for extra, why in zip(per_fil or [{}] * len(per_filament), per_filament, strict=False)
        ]
    if per_fil and "filaments" in meta:
        meta["filaments"] = [
            {**f, **extra} for f, extra in zip(meta["filaments"], per_fil, strict=False)
        ]
    units = dict(base.units)
    units.setdefault("segment_filament_id", "1")
    return replace(
        base,
        scalars=all_scalars,
        fields={**base.fields, **fields},
        static=static,
        programs=tuple(programs),
        units=units,
        metadata=to_jsonable(meta),
    )
