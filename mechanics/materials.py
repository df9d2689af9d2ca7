"""Sheet materials by name: Young's modulus, Poisson's ratio and density of what people fold.

Typical room-temperature values of the plain materials (datasheet ranges, mid values; a
particular grade or print differs by tens of per cent, so give ``E``, ``nu``, ``density``
yourself where it matters). Printed parts are anisotropic and weaker across layers; the values
are those of the filament.

======  =====================================  ========  ====  ===========
name    what                                   E (GPa)   nu    rho (kg/m3)
======  =====================================  ========  ====  ===========
paper   copy / origami paper, in plane         3.0       0.30  800
card    cardstock, in plane                    4.0       0.30  900
pet     PET film (Mylar)                       4.0       0.38  1390
pp      polypropylene sheet or print           1.5       0.42  905
petg    PETG print                             2.0       0.38  1270
pla     PLA print                              3.5       0.36  1240
tpu     TPU 95A print                          0.026     0.48  1210
steel   stainless steel sheet                  193       0.29  8000
al      aluminium sheet (5052)                 70        0.33  2680
paper2  the paper's simulations (Zhu, Filipov)  2.0       0.30  1200
======  =====================================  ========  ====  ===========
"""

from __future__ import annotations

from dataclasses import dataclass

from holofold.geometry.errors import ParameterError, check_range

__all__ = ["Material", "MATERIALS", "get_material"]


@dataclass(frozen=True)
class Material:
    """An isotropic linear-elastic sheet material.

    Attributes
    ----------
    name : str
    E : float
        Young's modulus, Pa.
    nu : float
        Poisson's ratio, in (-1, 0.5).
    density : float
        kg/m^3.
    description : str
    """

    name: str
    E: float
    nu: float
    density: float
    description: str = ""

    def __post_init__(self):
        check_range("E", self.E, 0.0, None, low_open=True)
        check_range("nu", self.nu, -1.0, 0.5, low_open=True, high_open=True)
        check_range("density", self.density, 0.0, None, low_open=True)


MATERIALS = {
    m.name: m
    for m in (
        Material("paper", 3.0e9, 0.30, 800.0, "copy or origami paper, in plane"),
        Material("card", 4.0e9, 0.30, 900.0, "cardstock, in plane"),
        Material("pet", 4.0e9, 0.38, 1390.0, "PET film (Mylar)"),
        Material("pp", 1.5e9, 0.42, 905.0, "polypropylene sheet or print"),
        Material("petg", 2.0e9, 0.38, 1270.0, "PETG print"),
        Material("pla", 3.5e9, 0.36, 1240.0, "PLA print"),
        Material("tpu", 26e6, 0.48, 1210.0, "TPU 95A print"),
        Material("steel", 193e9, 0.29, 8000.0, "stainless steel sheet"),
        Material("al", 70e9, 0.33, 2680.0, "aluminium sheet (5052)"),
        Material("paper2", 2.0e9, 0.30, 1200.0, "the values of the paper's simulations"),
    )
}


def get_material(name: str) -> Material:
    """The material called ``name`` (one of :data:`MATERIALS`)."""
    key = str(name).strip().lower()
    if key not in MATERIALS:
        raise ParameterError(f"material {name!r}; known: {', '.join(MATERIALS)}")
    return MATERIALS[key]
