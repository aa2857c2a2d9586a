"""The study's ring with a lightened flange: a part the gearbox parameters cannot describe.

The built-in ring's OCC solid of the study's gearbox (``flexgear.fe.mesh.component_brep``: toothed rim exactly of the
gear data, flange with its 12 bolt holes) with one kidney-shaped lightening slot through the flange between each
pair of bolts, written as STEP in millimetres (as ``flexgear export-geometry`` writes the built-in solids):

- each slot is centred on the bolt circle, halfway between two bolts; its width is the bolt hole's diameter and its
  centre line an arc of ``SLOT_ARC_DEG`` about the axis, closed by two half discs;
- the bolt holes and the bolts' clamped discs on the flange's +z face (``[joints_assumed] bolt_clamp_diameter_mm``)
  stay where the built-in ring has them: the nearest slot edge lies 7 mm beyond a clamped disc, so the bolted joint
  to the output shaft is the built-in one;
- the removed volume by hand (Pappus): per slot the arc band ``phi * r_c * w`` plus the two half discs
  ``pi w^2 / 4``, through the flange thickness ``t`` (:func:`removed_volume`).

Run from anywhere::

    .venv/bin/python examples/imported_ring/make_part.py                 # writes examples/imported_ring/parts/
    .venv/bin/python examples/imported_ring/make_part.py --out /tmp/parts

The solid is built in metres from the cached built-in ring (``FLEXGEAR_CACHE_DIR``, built on a cache miss).
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
STUDY_GEARBOX = HERE.parents[1] / "model_variants" / "gearbox.toml"
PART_NAME = "ring_lightened.step"
SLOT_ARC_DEG = 16.0
"""Angle [deg] of a slot's centre line about the axis (bolt pitch 30 deg; the slot ends' centres 7 deg from a bolt)."""
_OVERLAP = 1e-3
"""Axial overlap [m] of the cutters beyond the flange (no coplanar booleans)."""


@dataclass(frozen=True)
class Slots:
    """The lightening slots of the flange (metres, radians)."""

    count: int  # one between each pair of bolts
    circle_radius: float  # r_c: the bolt circle
    width: float  # w: the bolt hole's diameter
    arc: float  # phi: the centre line's angle about the axis
    z0: float  # the flange's -z face
    z1: float  # the flange's +z face (the bolted joint's plane)

    @property
    def angles(self) -> list[float]:
        """Polar angle [rad] of each slot's centre: halfway between bolt k (at 2 pi k / n) and bolt k + 1."""
        return [2 * math.pi * (k + 0.5) / self.count for k in range(self.count)]


def slots_of(spec) -> Slots:
    """The slots of the study ring's flange (:class:`Slots`), from the built-in ring's layout of ``spec``."""
    from flexgear.design import as_design

    flange = next(p for p in as_design(spec).layouts["ring"].prisms if p.section.holes)
    sec = flange.section
    return Slots(sec.holes, sec.hole_circle_radius, 2 * sec.hole_radius, math.radians(SLOT_ARC_DEG), flange.z0,
                 flange.z1)


def removed_volume(s: Slots) -> float:
    """The volume [m^3] the slots take out of the flange, by hand: n t (phi r_c w + pi w^2 / 4)."""
    return s.count * (s.z1 - s.z0) * (s.arc * s.circle_radius * s.width + math.pi * s.width ** 2 / 4)


def _cutter(s: Slots, angle: float):
    """One slot's cutter, through the flange with ``_OVERLAP`` beyond both faces: an annular sector of the slot's
    width over its arc, and a cylinder of the slot's width at each end."""
    import netgen.occ as occ

    z0, height = s.z0 - _OVERLAP, s.z1 - s.z0 + 2 * _OVERLAP
    r_in, r_out = s.circle_radius - s.width / 2, s.circle_radius + s.width / 2
    # the rectangle in the xz plane (y = 0; the work plane's local axes are x and z), turned about z over the arc
    plane = occ.WorkPlane(occ.Axes(occ.Pnt(0, 0, 0), n=-occ.Y, h=occ.X))
    rect = plane.MoveTo(r_in, z0).Rectangle(r_out - r_in, height).Face()
    band = rect.Revolve(occ.Axis(occ.Pnt(0, 0, 0), occ.Z), math.degrees(s.arc))
    band = band.Rotate(occ.Axis(occ.Pnt(0, 0, 0), occ.Z), math.degrees(angle - s.arc / 2))
    ends = [occ.Cylinder(occ.Pnt(s.circle_radius * math.cos(a), s.circle_radius * math.sin(a), z0), occ.Z,
                         s.width / 2, height) for a in (angle - s.arc / 2, angle + s.arc / 2)]
    return band + ends[0] + ends[1]


def lightened_ring(spec):
    """(the lightened ring's OCC solid in metres, the built-in ring's, :class:`Slots`)."""
    import netgen.occ as occ

    from flexgear.fe.mesh import component_brep

    ring = occ.OCCGeometry(str(component_brep(spec, "ring"))).shape.solids[0]
    s = slots_of(spec)
    cutters = [_cutter(s, a) for a in s.angles]
    part = ring - occ.Fuse(cutters)
    if len(part.solids) != 1:
        raise RuntimeError(f"the cut left {len(part.solids)} solids, expected one")
    return part.solids[0], ring, s


def write_part(out: Path, spec=None) -> Path:
    """Build the lightened ring of ``spec`` (default: the study's gearbox) and write it as STEP in mm into
    ``out/ring_lightened.step``; its path."""
    import netgen.occ as occ

    import flexgear as fg
    from flexgear.fe.geometry_export import STEP_UNIT_MM

    spec = fg.load_gearbox(STUDY_GEARBOX) if spec is None else spec
    part, ring, s = lightened_ring(spec)
    removed, by_hand = ring.mass - part.mass, removed_volume(s)
    if abs(removed / by_hand - 1) > 1e-6:
        raise RuntimeError(f"the cut removed {removed:.6e} m^3, by hand {by_hand:.6e} m^3")
    out.mkdir(parents=True, exist_ok=True)
    path = out / PART_NAME
    tmp = path.with_name(f".{path.name}.tmp.step")
    part.Scale(occ.Pnt(0, 0, 0), STEP_UNIT_MM).WriteStep(str(tmp))
    tmp.replace(path)
    return path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=HERE / "parts", help="output folder (default: %(default)s)")
    args = parser.parse_args(argv)
    path = write_part(args.out)
    print(f"wrote {path} ({path.stat().st_size / 1e6:.2f} MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
