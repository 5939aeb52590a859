"""Admissibility of a lattice state: can the printed stack be in it?

A lattice printed in N layers is one rod per edge whose section is the fused stack; its
layers' centre lines run at offsets along the transported material director m1
(:mod:`rotomorph.contact.stack`). A state is *admissible* when no layer of any segment
interpenetrates a layer of another segment it may touch (segments joined by a short path along
the network, and the layers of one segment, are one piece of material: the contact model's own
exclusion). :func:`admissibility` rebuilds every layer's centre line from a state's positions
and material frames and lists the layer pairs that interpenetrate; a state with any is not
physical, whatever the solver's convergence and stability say, and every output flags it.
A pressed contact may settle inside touching by less than the contact's offset (its compliant
zone, ``Contact.offset``: the barrier is infinite that far inside, so a state solved with the
stack in contact never goes deeper); only deeper overlaps count.

Every counted state, every figure's state and every candidate of the lift probe and the path
check goes through this one function (:mod:`rotomorph.lattice.heating`,
:mod:`rotomorph.simulate.report`, :mod:`rotomorph.io.validity`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray, IntArray
from rotomorph.contact.potential import DEFAULT_ACTIVATION, Contact
from rotomorph.contact.stack import Stack, StackOverlaps, stack_exclusion, stack_overlaps
from rotomorph.design.lattices import Lattice
from rotomorph.errors import InvalidParameterError
from rotomorph.rod.state import State

__all__ = ["Admissibility", "admissibility", "lattice_stack", "overlap_counts"]


def lattice_stack(lattice: Lattice) -> Stack:
    """The printed stack of ``lattice``: ``layers`` layers ``layer_height`` apart, centred."""
    return Stack.layered(lattice.layers, lattice.layer_height)


@dataclass(frozen=True, eq=False)
class Admissibility:
    """Which layer pairs of a lattice state interpenetrate.

    Attributes
    ----------
    overlaps
        The interpenetrating layer pairs (:class:`~rotomorph.contact.stack.StackOverlaps`).
    layers
        Layers of the stack that was checked.
    """

    overlaps: StackOverlaps
    layers: int

    @property
    def count(self) -> int:
        """Interpenetrating layer pairs (0: admissible)."""
        return self.overlaps.count

    @property
    def admissible(self) -> bool:
        """No two layers of segments that may touch interpenetrate."""
        return self.count == 0

    @property
    def deepest(self) -> float:
        """Largest penetration depth (mm; 0 when admissible)."""
        return self.overlaps.deepest

    def text(self) -> str:
        """One phrase for reports: what interpenetrates, or that nothing does."""
        if self.admissible:
            return f"no two layers interpenetrate ({self.layers}-layer stack)"
        pairs = len(self.overlaps.segment_pairs())
        return (
            f"{self.count} layer pairs of the printed {self.layers}-layer stack interpenetrate "
            f"({pairs} segment pairs, deepest {self.deepest:.3g} mm)"
        )


def _settings(lattice: Lattice, contact: Contact | None) -> tuple[float, float | None, float]:
    """Activation distance (mm) and reach (mm or None) of the exclusion, the contact's own, and
    its offset (mm): how far inside touching a pressed contact may settle (the barrier is
    infinite there; ``Contact.offset``, default the activation distance)."""
    if contact is None:
        dhat = DEFAULT_ACTIVATION * 2.0 * float(lattice.radius)
        return dhat, None, dhat
    r = contact.radii(lattice.network.n_edges)
    dhat = float(contact.activation_distance or DEFAULT_ACTIVATION * 2.0 * float(r.min()))
    offset = getattr(contact, "offset", None)
    return dhat, contact.reach, dhat if offset is None else float(offset)


def _excluded(lattice: Lattice, stack: Stack, dhat: float, reach: float | None) -> IntArray:
    key = ("stack_exclusion", stack.offsets, float(dhat), reach)
    cache = lattice._cache
    if key not in cache:
        net = lattice.network
        up = np.tile([0.0, 0.0, 1.0], (net.n_edges, 1))  # printed directors: the sheet normal
        radius = np.full(net.n_edges, float(lattice.radius))
        cache[key] = stack_exclusion(net.nodes, net.edges, up, radius, stack, dhat, reach)
    return cache[key]  # type: ignore[no-any-return]


def admissibility(
    lattice: Lattice,
    state: State | tuple[FloatArray, FloatArray],
    *,
    contact: Contact | None = None,
) -> Admissibility:
    """Rebuild every layer's centre line of ``state`` and find the interpenetrating pairs.

    Parameters
    ----------
    lattice
        The printed design (its layers, layer height and filament radius).
    state
        A :class:`~rotomorph.rod.state.State` of the lattice's rod model (positions and
        material frames), or ``(positions (N, 3) mm, material directors m1 (E, 3))``.
    contact
        The contact settings the state was solved with (their activation distance and reach
        decide which pairs are neighbours along the network); default the defaults.

    Returns
    -------
    Admissibility

    Raises
    ------
    InvalidParameterError
        A state whose shapes do not match the lattice's network.
    """
    net = lattice.network
    if isinstance(state, State):
        positions = state.positions
        directors, _ = state.material_directors()
    else:
        positions, directors = state
    positions = np.asarray(positions, dtype=float)
    directors = np.asarray(directors, dtype=float)
    if positions.shape != (net.n_nodes, 3) or directors.shape != (net.n_edges, 3):
        raise InvalidParameterError(
            "state",
            f"needs positions ({net.n_nodes}, 3) and directors ({net.n_edges}, 3) of this "
            f"lattice; got {positions.shape} and {directors.shape}",
        )
    stack = lattice_stack(lattice)
    dhat, reach, offset = _settings(lattice, contact)
    radius = np.full(net.n_edges, float(lattice.radius))
    found = stack_overlaps(
        positions, net.edges, directors, radius, stack, _excluded(lattice, stack, dhat, reach),
        tolerance=offset,
    )  # fmt: skip
    return Admissibility(found, stack.count)


def overlap_counts(lattice: Lattice, states: Any, *, contact: Contact | None = None) -> IntArray:
    """Interpenetrating layer pairs of every state in ``states`` ``(S,)``."""
    return np.array(
        [admissibility(lattice, s, contact=contact).count for s in states], dtype=np.int64
    )
