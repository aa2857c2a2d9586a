"""Recording and solving any flexgear model: sensors in, a pandas DataFrame with unit-named columns out.

``Recorder`` adds Exudyn sensors that store every step in memory (no Python per step) and turns them
into a DataFrame after the run: ``time_s`` plus one column per signal, the unit in the name
(``_rad_per_s``, ``_n``, ``_nm``, ``_m_per_s2``). ``solve`` integrates with the project's solver
choices (generalized-alpha, modified Newton, dense solver, one thread, no solution file).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from flexgear.mbs.bodies import Body
from flexgear.mbs.newton import newton_absolute_tolerance

if TYPE_CHECKING:
    from flexgear.mbs.gearbox import GearboxModel
    from flexgear.spec import Variant

__all__ = ["Recorder", "solver_settings", "solve", "simulation_settings", "add_gearbox_sensors", "joint_axis_torque"]


@dataclass
class Recorder:
    """Signals of a model, recorded at every step: call its methods before ``mbs.Assemble()``."""

    mbs: object
    _columns: dict[str, tuple[list[int], int, float]] = field(default_factory=dict)

    def add(self, name: str, unit: str, sensors: list[int], component: int, scale: float = 1.0) -> str:
        """Column ``f"{name}_{unit}"``: ``scale`` x the sum of component ``component`` of the sensors' values."""
        column = f"{name}_{unit}"
        if column in self._columns or column == "time_s":
            raise ValueError(f"column {column!r} is already recorded")
        self._columns[column] = (list(sensors), component, scale)
        return column

    def _node(self, node: int, output: str) -> int:
        import exudyn as exu
        from exudyn.itemInterface import SensorNode

        return self.mbs.AddSensor(SensorNode(nodeNumber=node, outputVariableType=getattr(exu.OutputVariableType,
                                                                                        output), storeInternal=True))

    def _object(self, obj: int, output: str) -> int:
        import exudyn as exu
        from exudyn.itemInterface import SensorObject

        return self.mbs.AddSensor(SensorObject(objectNumber=obj, outputVariableType=getattr(exu.OutputVariableType,
                                                                                          output), storeInternal=True))

    def speed(self, name: str, body: Body) -> str:
        """Spin speed of ``body`` about z [rad/s]: ``{name}_speed_rad_per_s``."""
        return self.add(f"{name}_speed", "rad_per_s", [self._node(body.node, "AngularVelocity")], 2)

    def mesh_force(self, name: str, springs: list[int]) -> str:
        """Normal mesh force [N], summed over the contacts (helix halves) ``springs``: ``{name}_force_n``."""
        return self.add(f"{name}_force", "n", [self._object(s, "Force") for s in springs], 0)

    def drive_torque(self, name: str, drive: int) -> str:
        """Torque [N m] the speed drive (flexgear.mbs.elements.add_speed_drive) applies: ``{name}_torque_nm``."""
        return self.add(f"{name}_torque", "nm", [self._object(drive, "Force")], 0, scale=-1.0)

    def acceleration(self, name: str, body: Body) -> tuple[str, str]:
        """Radial (x, y) acceleration of the body's frame [m/s^2]: ``{name}_accel_x_m_per_s2``, ``..._y_...``."""
        sensor = self._node(body.node, "Acceleration")
        return (self.add(f"{name}_accel_x", "m_per_s2", [sensor], 0),
                self.add(f"{name}_accel_y", "m_per_s2", [sensor], 1))

    def dataframe(self) -> pd.DataFrame:
        """The recorded signals after the run: ``time_s`` and one column per signal."""
        if not self._columns:
            raise ValueError("nothing recorded: add signals before mbs.Assemble()")
        cache: dict[int, np.ndarray] = {}

        def data(sensor: int) -> np.ndarray:
            if sensor not in cache:
                cache[sensor] = np.asarray(self.mbs.GetSensorStoredData(sensor))
            return cache[sensor]

        first = next(iter(self._columns.values()))[0][0]
        out = {"time_s": data(first)[:, 0]}
        for column, (sensors, component, scale) in self._columns.items():
            out[column] = scale * sum(data(s)[:, 1 + component] for s in sensors)
        return pd.DataFrame(out)


def solver_settings(t_end: float, step_size: float, spectral_radius: float = 0.8, newton_iterations: int = 3,
                    relative_tolerance: float = 1e-6, progress: bool = False, record_every_steps: int = 1,
                    reference: bool = False, absolute_tolerance: float | None = None):
    """Exudyn ``SimulationSettings``: generalized-alpha, modified Newton (Jacobian update after at most
    ``newton_iterations``), Eigen's sparse LU, one thread, no solution file, sensors every ``record_every_steps``
    steps. The LU keeps its ordering between Jacobians of one pattern, except in the ``reference`` formulation
    (a new ordering per Jacobian, Exudyn's default). ``absolute_tolerance``: Newton's absolute residual tolerance
    (flexgear.mbs.newton.newton_absolute_tolerance; None: Exudyn's). Times in s. The one solver set-up of the
    examples and the study."""
    import exudyn as exu

    if not (t_end > 0 and step_size > 0):
        raise ValueError(f"t_end and step_size must be > 0 [s], got {t_end}, {step_size}")
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.endTime = t_end
    ti.numberOfSteps = max(1, round(t_end / step_size))
    ti.generalizedAlpha.spectralRadius = spectral_radius
    ti.newton.useModifiedNewton = True
    ti.newton.maxModifiedNewtonIterations = newton_iterations
    ti.newton.relativeTolerance = relative_tolerance
    if absolute_tolerance is not None:
        ti.newton.absoluteTolerance = absolute_tolerance
    ti.verboseMode = 1 if progress else 0
    s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    s.linearSolver.reuseAnalyzedPattern = not reference
    s.parallel.numberOfThreads = 1
    s.solution.file.write = False
    s.solution.sensors.writePeriod = step_size * (record_every_steps - 0.5)
    return s


def solve(mbs, t_end: float, step_size: float, recorder: Recorder | None = None, progress: bool = False,
          **settings) -> pd.DataFrame | None:
    """Assemble and integrate ``mbs`` to ``t_end`` [s]; returns the recorder's DataFrame (or None).

    ``settings``: further :func:`solver_settings` arguments.
    """
    import exudyn as exu

    mbs.Assemble()
    mbs.SolveDynamic(solver_settings(t_end, step_size, progress=progress, **settings),
                     solverType=exu.DynamicSolverType.GeneralizedAlpha)
    return None if recorder is None else recorder.dataframe()


def simulation_settings(variant: Variant, t_end: float, progress: bool, warm_start: bool = False):
    """:func:`solver_settings` for the variant's load case (Table 5 step size) and solver assumptions. ``warm_start``:
    the run warm-starts the multipliers (:class:`flexgear.mbs.newton.MultiplierWarmStart`) and takes the absolute
    tolerance that goes with it (:func:`flexgear.mbs.newton.newton_absolute_tolerance`)."""
    sv = variant.gearbox.solver_assumed
    return solver_settings(t_end, variant.gearbox.load_case.step_size_s, sv.spectral_radius,
                           sv.newton_max_modified_iterations, sv.newton_relative_tolerance, progress,
                           sv.record_every_steps, sv.reference,
                           newton_absolute_tolerance(variant.gearbox) if warm_start else None)


def add_gearbox_sensors(mbs, model: GearboxModel) -> dict[str, int]:
    """Sensors of the study's gearbox (speeds, drive torque, bearing accelerations, joints, modes, mesh forces)."""
    import exudyn as exu
    from exudyn.itemInterface import SensorNode, SensorObject

    ovt = exu.OutputVariableType
    sun, ring = model.bodies[model.input_body].node, model.bodies[model.output_body].node
    sensors = {
        "input_speed": mbs.AddSensor(SensorNode(nodeNumber=sun, outputVariableType=ovt.AngularVelocity,
                                                storeInternal=True)),
        "output_speed": mbs.AddSensor(SensorNode(nodeNumber=ring, outputVariableType=ovt.AngularVelocity,
                                                 storeInternal=True)),
        "input_torque": mbs.AddSensor(SensorObject(objectNumber=model.drive, outputVariableType=ovt.Force,
                                                   storeInternal=True)),
        "input_accel": mbs.AddSensor(SensorNode(nodeNumber=sun, outputVariableType=ovt.Acceleration,
                                                storeInternal=True)),
        "output_accel": mbs.AddSensor(SensorNode(nodeNumber=ring, outputVariableType=ovt.Acceleration,
                                                 storeInternal=True)),
    }
    sensors["output_spin"] = mbs.AddSensor(SensorNode(nodeNumber=model.output_spin[0],
                                                      outputVariableType=ovt.Coordinates, storeInternal=True))
    for gear, joints in model.joints.items():
        for k, (joint, _) in enumerate(joints):
            if gear in model.linear_joints:  # multipliers: force [N] and moment [N m], ground or body axes (joints)
                sensors[f"joint_{gear}_{k}"] = mbs.AddSensor(SensorObject(
                    objectNumber=joint, outputVariableType=ovt.Force, storeInternal=True))
                continue
            sensors[f"joint_{gear}_{k}"] = mbs.AddSensor(SensorObject(
                objectNumber=joint, outputVariableType=ovt.TorqueLocal, storeInternal=True))
    if model.kinematics is not None:
        for k, node in enumerate(model.aux_nodes):  # the contacts' deflections, pair by pair (rows in order)
            sensors[f"deflections/{k}"] = mbs.AddSensor(SensorNode(nodeNumber=node, outputVariableType=ovt.Coordinates,
                                                                   storeInternal=True))
        if model.residual is not None:
            sensors["residual"] = mbs.AddSensor(SensorNode(nodeNumber=model.residual_node,
                                                           outputVariableType=ovt.Coordinates, storeInternal=True))
        for k, node in enumerate(model.seat_residual_nodes):  # e_s of residual.seat_bodies, in order
            sensors[f"seat_residual/{k}"] = mbs.AddSensor(SensorNode(
                nodeNumber=node, outputVariableType=ovt.Coordinates, storeInternal=True))
        for name, body in model.bodies.items():
            for k, node in enumerate(body.modal_nodes if body.flexible else ()):  # q~ node by node, in order
                sensors[f"modes_{name}/{k}"] = mbs.AddSensor(SensorNode(
                    nodeNumber=node, outputVariableType=ovt.Coordinates, storeInternal=True))
    for kind, groups in (("outer", model.outer_contacts), ("inner", model.inner_contacts)):
        for i, halves in enumerate(groups):
            for h, obj in enumerate(halves):
                sensors[f"{kind}_{i + 1}_{h}"] = mbs.AddSensor(SensorObject(
                    objectNumber=obj, outputVariableType=ovt.Force, storeInternal=True))
    return sensors


def joint_axis_torque(mbs, model: GearboxModel, sensors: dict[str, int], gear: str) -> tuple[np.ndarray, np.ndarray]:
    """Time [s] and the torque [N·m] about the axis that ``gear``'s joint to its shaft transmits.

    The joint lies on the axis (flexgear.fe.reduced.gear_shaft_joints), so its forces have no moment about it:
    T_z is the joint's moment M_z, the multiplier's sixth entry of a linear joint (flexgear.mbs.joints, on the
    shaft), ``TorqueLocal`` z of Exudyn's generic joint (the reference formulation; local frames share the axis).
    """
    total = None
    for k, _ in enumerate(model.joints[gear]):
        data = np.asarray(mbs.GetSensorStoredData(sensors[f"joint_{gear}_{k}"]))
        torque = data[:, 6] if gear in model.linear_joints else data[:, 3]
        total = torque.copy() if total is None else total + torque
    return data[:, 0], total
