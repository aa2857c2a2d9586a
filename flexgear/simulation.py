"""A thin facade over the stages: a gearbox (and which components are flexible) in, runs, linear models, modes and
reports out.

    import flexgear as fg

    sim = fg.Simulation.from_gearbox("examples/spur_star/gearbox.toml", flexible=("ring",))
    run = sim.run(t_end_s=0.05)          # flexgear.results.RunResult: run.signals, run.meta
    sim.theory.ratio, run.signals.transmission_ratio.iloc[-1]
    sim.modes(f_max_hz=5000.0)           # the star only: flexgear.modal.Modes at the operating point

Each method calls the stage that owns the work (flexgear.mbs.run, flexgear.lumped.run, flexgear.modal,
flexgear.report) with this simulation's variant; nothing is kept between calls but the variant itself, so a
Simulation is as cheap to make as loading its file. The command line (flexgear.cli) does the same per subcommand.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from flexgear.spec import (
    CARRIER,
    OPTIONAL_COMPONENTS,
    GearboxSpec,
    SpecError,
    Variant,
    check_carrier,
    load_gearbox,
    load_variant,
    stage_components,
)
from flexgear.theory import Theory, theory

__all__ = ["Simulation"]


@dataclass(frozen=True)
class Simulation:
    """One variant of a gearbox: each component rigid or flexible (Table 3's columns), at one mesh level."""

    variant: Variant

    @classmethod
    def from_file(cls, path: str | Path) -> Simulation:
        """From a variant file (``gearbox = "..."`` and ``[components]``, flexgear.spec.load_variant)."""
        return cls(load_variant(path))

    @classmethod
    def from_gearbox(cls, gearbox: str | Path | GearboxSpec, flexible: Iterable[str] = (), *, name: str = "",
                     mesh_level: str = "coarse", rigid_mass_properties: str = "mesh") -> Simulation:
        """From a gearbox file (or a loaded spec): the components named in ``flexible`` flexible (any of
        flexgear.spec.stage_components of its arrangement, and the planetary stage's ``carrier``), the others rigid.
        ``rigid_mass_properties``: "mesh" (the reduced bodies', rigid and flexible twins identical) or "exact" (the
        exact geometry's: no meshing for a rigid variant)."""
        spec = gearbox if isinstance(gearbox, GearboxSpec) else load_gearbox(gearbox)
        flexible = tuple(flexible)
        known = stage_components(spec.gears) + OPTIONAL_COMPONENTS
        for component in flexible:
            if component not in known:
                raise SpecError(spec.source, f"components.{component}", f"unknown component; allowed: "
                                f"{', '.join(known)}")
        if mesh_level not in spec.meshing_assumed:
            raise SpecError(spec.source, "mesh_level", f"expected one of {sorted(spec.meshing_assumed)}", mesh_level)
        if rigid_mass_properties not in ("mesh", "exact"):
            raise SpecError(spec.source, "rigid_mass_properties", "expected one of 'mesh', 'exact'",
                            rigid_mass_properties)
        components = {c: ("flexible" if c in flexible else "rigid") for c in stage_components(spec.gears)}
        if CARRIER in flexible:
            components[CARRIER] = "flexible"
        check_carrier(spec.source, components, spec)
        label = name or ("rigid" if not flexible else "flexible_" + "_".join(flexible))
        return cls(Variant(spec.source, label, spec, components, mesh_level, rigid_mass_properties))

    # ------------------------------------------------------------------ what the gearbox is
    @property
    def gearbox(self) -> GearboxSpec:
        return self.variant.gearbox

    @property
    def theory(self) -> Theory:
        """Loss-free theory of the load case (speeds, ratio, torques, mesh force and frequency; flexgear.theory)."""
        return theory(self.gearbox)

    def with_gearbox(self, table: str, **fields: Any) -> Simulation:
        """The same variant with single fields of one gearbox table changed (``sim.with_gearbox("load_case",
        load_torque_nm=300.0)``). Sizes derived from the gear set are not derived again: load the changed file."""
        return Simulation(replace(self.variant, gearbox=self.gearbox.with_fields(table, **fields)))

    # ------------------------------------------------------------------ the stages
    def run(self, t_end_s: float | str | None = None, progress: bool = False, **options: Any):
        """The multibody run (flexgear.mbs.run.run_variant): a flexgear.results.RunResult."""
        from flexgear.mbs.run import run_variant

        return run_variant(self.variant, t_end_s, progress, **options)

    def lumped(self, t_end_s: float | str | None = None, progress: bool = False):
        """The lumped-parameter model of the gearbox (eq. 1-13, flexgear.lumped.run.run_lumped): a RunResult."""
        from flexgear.lumped.run import run_lumped

        return run_lumped(self.gearbox, t_end_s, progress)

    def linearize(self, speed_rpm: float | None = None, **options: Any):
        """The linear model at the operating point (flexgear.modal.linear.linearize; the star arrangement)."""
        from flexgear.modal.linear import linearize

        return linearize(self.variant, speed_rpm, **options)

    def modes(self, f_max_hz: float | None = None, speed_rpm: float | None = None):
        """The modes at the operating point up to ``f_max_hz`` [Hz] (flexgear.modal.eigenmodes.modes)."""
        from flexgear.modal.eigenmodes import modes

        return modes(self.linearize(speed_rpm), f_max_hz)

    def campbell(self, speeds_rpm: Sequence[float], f_max_hz: float | None = None):
        """The Campbell diagram over ``speeds_rpm`` [rpm] (flexgear.modal.campbell_diagram.campbell)."""
        from flexgear.modal.campbell_diagram import campbell

        return campbell(self.variant, speeds_rpm, f_max_hz)

    @staticmethod
    def matrix(variant_files: Sequence[str | Path], out_dir: str | Path, **options: Any):
        """Run and screen a matrix of variant files into ``out_dir`` (flexgear.study.matrix.run_matrix)."""
        from flexgear.study.matrix import run_matrix

        return run_matrix(variant_files, out_dir, **options)

    @staticmethod
    def report(results_dir: str | Path, output: str | Path, **options: Any) -> Path:
        """The PDF screening report of a results folder (flexgear.report.pages.build_report)."""
        from flexgear.report.pages import build_report

        return build_report(results_dir, output, **options)
