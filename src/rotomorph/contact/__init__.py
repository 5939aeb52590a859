"""Contact: filaments that touch each other and rigid obstacles, never pass through.

Contact is an energy term beside the rod's (a barrier on the distance offset by the filament
thickness) with exact gradients and Hessians, plus a provably collision-free step bound that
the Newton solver takes as its ``max_step``. See ``docs/contact.md``.
"""

from rotomorph.contact.obstacles import Cylinder, Floor, Obstacle, Sphere
from rotomorph.contact.potential import Contact, ContactPotential, InfeasibleContactError

__all__ = [
    "Contact",
    "ContactPotential",
    "Cylinder",
    "Floor",
    "InfeasibleContactError",
    "Obstacle",
    "Sphere",
]
