"""Inks of a Janus filament as values, and the name registry of the default inks.

The two inks of the seed paper (Abdelrahman et al., "Rotational 3D printing of active-passive
filaments and lattices with programmable shape morphing") ship as the default materials file
``data/paper_inks.toml`` (:mod:`rotomorph.materials.parameter_set`), every value with its unit
and provenance; a :class:`Material` is one ink's values at the print temperature, with the
sources and the assumptions listed. Stiffer passive blends (paper, Methods: stiffer ink :
passive ink = 1:10 and 1:4) have no measured modulus; :func:`blend_material` derives a
placeholder by a stated mixing rule from a *user-supplied* stiff-ink modulus.

Registry: :func:`get_material`, :func:`register_material`, :func:`known_materials`.
Built-in names: the default file's ``"lce"`` (active) and ``"acrylate"`` (passive), and
``"acrylate_1to10"`` and ``"acrylate_1to4"`` (placeholder blends, see
:data:`PLACEHOLDER_STIFF_INK_MODULUS`). A lab's own inks live in its own materials file, named
by its designs (``materials = "inks.toml"``), not in this registry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

from rotomorph.errors import MaterialError

Kind = Literal["active", "passive"]

#: Placeholder Young's modulus (MPa) of the stiff ink (Ebecryl 8413 + PETA, 10 wt.% silica).
#: NOT measured in the paper: an order-of-magnitude guess for a highly cross-linked acrylate, used
#: only to give the built-in blends a value. Pass your own measurement to :func:`blend_material`.
PLACEHOLDER_STIFF_INK_MODULUS = 100.0


def _check_finite(name: str, value: float, *, positive: bool = False) -> None:
    if not math.isfinite(value):
        raise MaterialError(name, f"must be a finite number; got {value!r}")
    if positive and value <= 0.0:
        raise MaterialError(name, f"must be > 0; got {value!r}")


@dataclass(frozen=True)
class Material:
    """One ink of a printed filament (values at 25 °C unless stated).

    Parameters
    ----------
    name
        Registry key (lower case, no spaces), e.g. ``"lce"``.
    kind
        ``"active"`` (liquid-crystal elastomer, actuates through T_NI) or ``"passive"``.
    youngs_modulus
        Young's modulus E at 25 °C (MPa).
    poisson_ratio
        Poisson ratio ν in (-1, 0.5] (dimensionless); shear modulus G = E / (2 (1 + ν)).
    glass_transition
        Glass-transition temperature T_g (°C); ``None`` when not known.
    transition_temperature
        Nematic-to-isotropic temperature T_NI (°C); ``None`` when unknown or not applicable.
    actuation_length
        Free normalized length L/L0 of a bulk sample heated to the actuation temperature
        (dimensionless; 0.67 pure LCE, 1.03 passive at 150 °C, paper Fig. 1D/E).
    density
        Mass density (g/cm³). Not given in the paper: an assumption (see ``assumptions``).
    youngs_modulus_spread, actuation_length_spread
        Reported standard deviations (MPa, dimensionless); 0 when unknown.
    source
        Where the measured values come from (figure / section of the paper).
    assumptions
        Values that are modelling choices or placeholders rather than measurements.

    Raises
    ------
    MaterialError
        Empty name, unknown kind, non-finite or non-positive moduli, lengths or densities, a
        Poisson ratio outside (-1, 0.5], or an active material without T_NI.
    """

    name: str
    kind: Kind
    youngs_modulus: float
    poisson_ratio: float
    glass_transition: float | None
    transition_temperature: float | None
    actuation_length: float
    density: float
    youngs_modulus_spread: float = 0.0
    actuation_length_spread: float = 0.0
    source: tuple[str, ...] = field(default_factory=tuple)
    assumptions: tuple[str, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        if not self.name or self.name != self.name.strip() or " " in self.name:
            raise MaterialError("Material.name", f"must be a non-empty word; got {self.name!r}")
        if self.kind not in ("active", "passive"):
            raise MaterialError(
                "Material.kind", f"must be 'active' or 'passive'; got {self.kind!r}"
            )
        _check_finite("Material.youngs_modulus", self.youngs_modulus, positive=True)
        _check_finite("Material.actuation_length", self.actuation_length, positive=True)
        _check_finite("Material.density", self.density, positive=True)
        if self.glass_transition is not None:
            _check_finite("Material.glass_transition", self.glass_transition)
            if self.glass_transition < -273.15:
                raise MaterialError("Material.glass_transition", "must be >= -273.15 °C")
        _check_finite("Material.poisson_ratio", self.poisson_ratio)
        if not -1.0 < self.poisson_ratio <= 0.5:
            raise MaterialError(
                "Material.poisson_ratio", f"must lie in (-1, 0.5]; got {self.poisson_ratio}"
            )
        for name in ("youngs_modulus_spread", "actuation_length_spread"):
            value = getattr(self, name)
            _check_finite(f"Material.{name}", value)
            if value < 0.0:
                raise MaterialError(f"Material.{name}", f"must be >= 0; got {value}")
        if self.transition_temperature is not None:
            _check_finite("Material.transition_temperature", self.transition_temperature)
        elif self.kind == "active":
            raise MaterialError(
                "Material.transition_temperature",
                "an active material needs T_NI (°C); give a measured value or a placeholder",
            )
        object.__setattr__(self, "source", tuple(self.source))
        object.__setattr__(self, "assumptions", tuple(self.assumptions))

    @property
    def shear_modulus(self) -> float:
        """Shear modulus G = E / (2 (1 + ν)) at 25 °C (MPa)."""
        return self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def is_active(self) -> bool:
        """Whether the material actuates (liquid-crystal elastomer)."""
        return self.kind == "active"

    def free_strain(self, measure: Literal["hencky", "engineering"] = "hencky") -> float:
        """Free axial strain of a bulk sample at actuation (dimensionless).

        Parameters
        ----------
        measure
            ``"hencky"``: ln(L/L0); ``"engineering"``: L/L0 - 1.

        Examples
        --------
        The passive acrylate (L/L0 = 1.03) gives 0.03 (engineering) or ln 1.03 = 0.0296 (Hencky).
        """
        if measure == "hencky":
            return math.log(self.actuation_length)
        if measure == "engineering":
            return self.actuation_length - 1.0
        raise MaterialError("measure", f"must be 'hencky' or 'engineering'; got {measure!r}")


def blend_material(
    passive: Material,
    stiff_modulus: float,
    stiff_parts: float,
    passive_parts: float,
    *,
    name: str | None = None,
    rule: Literal["logarithmic", "voigt", "reuss"] = "logarithmic",
) -> Material:
    """Passive ink blended with a stiffer ink (paper, Methods: ratios 1:10 and 1:4).

    The paper gives no modulus for the blends. This returns a *placeholder* from a mixing rule
    with volume fraction φ = stiff_parts / (stiff_parts + passive_parts) (equal ink densities
    assumed):

    * ``"logarithmic"`` (Lichtenecker): ln E = φ ln E_s + (1 - φ) ln E_p (default; between the
      bounds, appropriate for an interpenetrating cured blend),
    * ``"voigt"``: E = φ E_s + (1 - φ) E_p (upper bound),
    * ``"reuss"``: 1/E = φ/E_s + (1 - φ)/E_p (lower bound).

    Every other property is taken from ``passive``; the result lists the rule in ``assumptions``.

    Parameters
    ----------
    passive
        The passive base ink.
    stiff_modulus
        Young's modulus of the stiff ink E_s (MPa); user supplied (no measured value exists).
    stiff_parts, passive_parts
        Mixing ratio by weight, stiff : passive (e.g. 1 and 10).
    name
        Registry name; default ``f"{passive.name}_{a}to{b}"``.
    rule
        Mixing rule (see above).

    Returns
    -------
    Material
        Passive material with the blended modulus (MPa).

    Raises
    ------
    MaterialError
        Non-positive modulus or parts, unknown rule, or an active base material.
    """
    if passive.kind != "passive":
        raise MaterialError(
            "blend_material.passive", f"must be a passive material; got {passive.name}"
        )
    _check_finite("blend_material.stiff_modulus", stiff_modulus, positive=True)
    _check_finite("blend_material.stiff_parts", stiff_parts, positive=True)
    _check_finite("blend_material.passive_parts", passive_parts, positive=True)
    phi = stiff_parts / (stiff_parts + passive_parts)
    e_p = passive.youngs_modulus
    if rule == "logarithmic":
        modulus = math.exp(phi * math.log(stiff_modulus) + (1.0 - phi) * math.log(e_p))
    elif rule == "voigt":
        modulus = phi * stiff_modulus + (1.0 - phi) * e_p
    elif rule == "reuss":
        modulus = 1.0 / (phi / stiff_modulus + (1.0 - phi) / e_p)
    else:
        raise MaterialError(
            "blend_material.rule", f"must be 'logarithmic', 'voigt' or 'reuss'; got {rule!r}"
        )
    label = f"{passive.name}_{stiff_parts:g}to{passive_parts:g}" if name is None else name
    return Material(
        name=label,
        kind="passive",
        youngs_modulus=modulus,
        poisson_ratio=passive.poisson_ratio,
        glass_transition=passive.glass_transition,
        transition_temperature=passive.transition_temperature,
        actuation_length=passive.actuation_length,
        density=passive.density,
        source=("paper Methods: stiffer ink : passive ink blends 1:10 and 1:4 (no modulus given)",),
        assumptions=(
            f"PLACEHOLDER modulus by {rule} mixing rule, phi = {phi:.4f} (equal densities), "
            f"stiff-ink modulus {stiff_modulus:g} MPa supplied by the user",
            "free strain, Tg and density copied from the base passive ink",
            *passive.assumptions,
        ),
    )


def _builtin_registry() -> dict[str, Material]:
    from rotomorph.materials.parameter_set import default_materials  # it builds Materials

    reg = default_materials().materials
    base = reg["acrylate"]
    for parts in (10, 4):
        blend = blend_material(base, PLACEHOLDER_STIFF_INK_MODULUS, 1, parts)
        reg[blend.name] = blend
    return reg


_REGISTRY: dict[str, Material] = {}


def _registry() -> dict[str, Material]:
    """The registry, filled with the default inks on first use."""
    if not _REGISTRY:
        _REGISTRY.update(_builtin_registry())
    return _REGISTRY


def known_materials() -> tuple[str, ...]:
    """Names of all registered materials, sorted."""
    return tuple(sorted(_registry()))


def get_material(name: str) -> Material:
    """Look up a registered material by name (case-insensitive).

    Raises
    ------
    MaterialError
        Unknown name; the message lists the known names.
    """
    key = str(name).strip().lower()
    try:
        return _registry()[key]
    except KeyError:
        raise MaterialError(
            "material",
            f"unknown material {name!r}; known: {', '.join(known_materials())} "
            "(add one with register_material)",
        ) from None


def register_material(material: Material, *, overwrite: bool = False) -> Material:
    """Add ``material`` to the registry under ``material.name`` (lower-cased) and return it.

    Raises
    ------
    MaterialError
        The name exists and ``overwrite`` is false, or ``material`` is not a :class:`Material`.
    """
    if not isinstance(material, Material):
        raise MaterialError("register_material.material", "must be a Material instance")
    key = material.name.lower()
    if key in _registry() and not overwrite:
        raise MaterialError(
            "register_material.material",
            f"{key!r} is already registered; pass overwrite=True to replace it",
        )
    _REGISTRY[key] = material
    return material
