"""The exact mass properties of a component from the user's file (``[components_geometry]``), for the design.

The design (flexgear.design) holds every component's exact mass, centre of mass and inertia: the lumped model and
the rigid components of a variant with ``rigid_mass_properties = "exact"`` read them. For a part from a file they
are the file's geometry, not the built-in layout's:

- a STEP or BREP solid: its volume integrals (OCC, flexgear.geometry.solids.occ_mass_properties), of the solid as
  flexgear.fe.imported reads and places it;
- a volume mesh: its integrals over its own elements (flexgear.fe.fem.FEModel.mass_properties: the consistent mass
  matrix at the mesh's element order, exact for the meshed geometry, m = 1^T M_s 1, m c = X^T M_s 1,
  J = tr(Q) I - Q with Q = X^T M_s X - m c c^T), at the highest element order of the gearbox's mesh levels.

:func:`imported_mass_properties` is registered with flexgear.design when flexgear.fe is imported, so that the
design stage needs no import of the FE stage.
"""

from __future__ import annotations

from flexgear.design import Design, register_part_masses
from flexgear.geometry.massprops import MassProperties
from flexgear.schema import CARRIER

__all__ = ["imported_mass_properties"]


def imported_mass_properties(d: Design, component: str) -> MassProperties:
    """Mass [kg], centre of mass [m] and inertia about it [kg m^2] of ``component``'s part from its file, for the
    design ``d`` (module docstring)."""
    from flexgear.fe.imported import imported_brep, imported_mesh

    spec = d.spec
    entry = spec.components_geometry[component]
    rho = spec.material_assumed.density_kg_m3
    level = max(spec.meshing_assumed, key=lambda name: spec.meshing_assumed[name].element_order)
    if component == CARRIER:  # no layout: the solid as flexgear.fe.carrier_part reads it, or its mesh's FE model
        from flexgear.fe.carrier import carrier_fe_model
        from flexgear.fe.imported import read_solid
        from flexgear.geometry.carrier import carrier_sizes
        from flexgear.geometry.solids import occ_mass_properties

        if entry.kind == "mesh":
            return carrier_fe_model(spec, level).mass_properties()
        solid = read_solid(component, entry, carrier_sizes(spec).plate_outer_radius)
        return MassProperties(*occ_mass_properties(solid, rho))
    if entry.kind != "mesh":
        from netgen.occ import OCCGeometry

        from flexgear.geometry.solids import occ_mass_properties

        solid = OCCGeometry(str(imported_brep(d, component))).shape.solids[0]
        return MassProperties(*occ_mass_properties(solid, rho))
    from flexgear.fe.fem import fe_model

    order = spec.meshing_assumed[level].element_order
    mesh = imported_mesh(d, component, level, order)
    return fe_model(mesh.ngsolve_mesh(), spec.material_assumed, order).mass_properties()


register_part_masses(imported_mass_properties)
