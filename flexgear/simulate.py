"""Simulation (Exudyn backend): build a variant, integrate the load case, return a RunResult.

Solver: generalized-alpha (spectral radius from ``[solver_assumed]``), modified Newton with a
Jacobian update after at most ``newton_max_modified_iterations`` iterations, dense linear solver,
one thread, no solution file; sensors store every ``record_every_steps``-th step in memory.
"""

from __future__ import annotations

import datetime as _dt
import math
import platform
import time
import traceback
from importlib import metadata

import numpy as np
import pandas as pd

from flexgear.model import GearboxModel, MassSource, ReducedSource, build_star_gearbox
from flexgear.results import RunResult, signal_columns
from flexgear.spec import Variant, as_dict, spec_hash

__all__ = ["run_variant", "simulation_settings", "versions"]


def versions() -> dict[str, str]:
    """Versions of Python and the packages a result depends on."""
    out = {"python": platform.python_version()}
    for pkg in ("flexgear", "exudyn", "numpy", "scipy", "ngsolve", "pandas"):
        try:
            out[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            out[pkg] = "not installed"
    return out


def simulation_settings(variant: Variant, t_end: float, progress: bool):
    """Exudyn ``SimulationSettings`` for the variant's load case and solver assumptions."""
    import exudyn as exu

    lc, sv = variant.gearbox.load_case, variant.gearbox.solver_assumed
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.endTime = t_end
    ti.numberOfSteps = max(1, round(t_end / lc.step_size_s))
    ti.generalizedAlpha.spectralRadius = sv.spectral_radius
    ti.newton.useModifiedNewton = True
    ti.newton.maxModifiedNewtonIterations = sv.newton_max_modified_iterations
    ti.newton.relativeTolerance = sv.newton_relative_tolerance
    ti.verboseMode = 1 if progress else 0
    s.linearSolver.solverType = (exu.LinearSolverType.EigenSparse if sv.linear_solver == "sparse"
                                 else exu.LinearSolverType.EXUdense)
    s.parallel.numberOfThreads = 1
    s.solution.file.write = False
    s.solution.sensors.writePeriod = lc.step_size_s * (sv.record_every_steps - 0.5)
    return s


def _add_sensors(mbs, model: GearboxModel) -> dict[str, int]:
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
    for gear, joint in model.joints.items():
        sensors[f"joint_{gear}"] = mbs.AddSensor(SensorObject(objectNumber=joint, outputVariableType=ovt.TorqueLocal,
                                                              storeInternal=True))
    if model.kinematics is not None:
        sensors["deflections"] = mbs.AddSensor(SensorNode(nodeNumber=model.aux_node,
                                                          outputVariableType=ovt.Coordinates, storeInternal=True))
        for name, body in model.bodies.items():
            if body.flexible:
                sensors[f"modes_{name}"] = mbs.AddSensor(SensorNode(
                    nodeNumber=body.modal_node, outputVariableType=ovt.Coordinates, storeInternal=True))
    for kind, groups in (("outer", model.outer_contacts), ("inner", model.inner_contacts)):
        for i, halves in enumerate(groups):
            for h, obj in enumerate(halves):
                sensors[f"{kind}_{i + 1}_{h}"] = mbs.AddSensor(SensorObject(
                    objectNumber=obj, outputVariableType=ovt.Force, storeInternal=True))
    return sensors


def _signals(mbs, model: GearboxModel, sensors: dict[str, int]) -> pd.DataFrame:
    """Signal table (flexgear.results.signal_columns) from the stored sensor data."""
    def data(key: str) -> np.ndarray:
        return np.asarray(mbs.GetSensorStoredData(sensors[key]))

    speed_in, speed_out = data("input_speed"), data("output_speed")
    n = model.spec.gears.planet_count
    cols: dict[str, np.ndarray] = {"time_s": speed_in[:, 0]}
    cols["input_speed_deg_per_s"] = np.degrees(speed_in[:, 3])
    cols["output_speed_deg_per_s"] = np.degrees(speed_out[:, 3])
    with np.errstate(divide="ignore", invalid="ignore"):
        cols["transmission_ratio"] = np.where(speed_in[:, 3] != 0, speed_out[:, 3] / speed_in[:, 3], np.nan)
    cols["input_torque_nm"] = -data("input_torque")[:, 1]  # constraint reaction -> torque applied by the drive
    for kind in ("outer", "inner"):
        for i in range(1, n + 1):
            halves = [k for k in sensors if k.startswith(f"{kind}_{i}_")]
            cols[f"{kind}_mesh_force_{i}_n"] = sum(data(k)[:, 1] for k in halves)
    for side, key in (("input", "input_accel"), ("output", "output_accel")):
        acc = data(key)
        cols[f"{side}_bearing_accel_x_m_per_s2"] = acc[:, 1]
        cols[f"{side}_bearing_accel_y_m_per_s2"] = acc[:, 2]
    return pd.DataFrame({c: cols[c] for c in signal_columns(n)})


def elastic_share(mbs, model: GearboxModel, sensors: dict[str, int], window_start: float) -> dict[str, float]:
    """Share of the mesh approach taken up by the flexible gears' elastic deformation, per mesh kind.

    The contact coordinate is the penetration delta = (rigid approach) + (elastic terms), where the
    elastic terms are negative when the gears yield under the mesh force: share = -mean(elastic) / mean(delta).
    """
    kin = model.kinematics
    defl = np.asarray(mbs.GetSensorStoredData(sensors["deflections"]))
    keep = np.flatnonzero(defl[:, 0] >= window_start)[::10]
    modal = [np.asarray(mbs.GetSensorStoredData(sensors[k]))[:, 1:] for k in sensors if k.startswith("modes_")]
    q = np.hstack(modal)
    first = kin.base.shape[1] - q.shape[1]
    elastic = np.array([kin.matrix_at(defl[k, 0])[:, first:] @ q[k] for k in keep])
    total = defl[keep, 1:]
    out = {}
    for kind in ("outer", "inner"):
        rows = [i for i, c in enumerate(model.contacts) if c.name.startswith(kind)]
        out[f"elastic_share_{kind}"] = float(-elastic[:, rows].mean() / total[:, rows].mean())
    return out


def _meta(variant: Variant, t_end: float) -> dict:
    from flexgear.theory import theory

    th = theory(variant.gearbox)
    lc = variant.gearbox.load_case
    return {
        "variant": variant.name, "backend": "exudyn", "source": str(variant.source),
        "config_hash": spec_hash(variant, t_end), "components": dict(variant.components),
        "t_end_s": t_end, "step_size_s": lc.step_size_s, "ramp_time_s": lc.ramp_time_s,
        "planet_count": variant.gearbox.gears.planet_count,
        "theory": {
            "input_speed_deg_per_s": th.input_speed_deg_per_s, "output_speed_deg_per_s": th.output_speed_deg_per_s,
            "ratio": th.ratio, "input_torque_nm": th.input_torque, "output_torque_nm": th.output_torque,
            "mesh_force_n": th.mesh_force, "mesh_frequency_hz": th.mesh_frequency,
        },
        "spec": as_dict(variant.gearbox), "versions": versions(),
        "created": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
    }


def run_variant(variant: Variant, t_end_s: float | None = None, progress: bool = False,
                mass_source: MassSource | None = None, reduced_source: ReducedSource | None = None) -> RunResult:
    """Run ``variant`` for ``t_end_s`` (default: the load case's end time).

    Never raises for a model or solver failure: the result then has status "failed" and the reason.
    """
    import exudyn as exu

    t_end = variant.gearbox.load_case.end_time_s if t_end_s is None else float(t_end_s)
    meta = _meta(variant, t_end)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    try:
        if not (t_end > 0 and math.isfinite(t_end)):
            raise ValueError(f"t_end_s must be a positive number, got {t_end_s!r}")
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        model = build_star_gearbox(mbs, variant, mass_source, reduced_source)
        sensors = _add_sensors(mbs, model)
        mbs.Assemble()
        build_s = time.perf_counter() - wall0
        mbs.SolveDynamic(simulation_settings(variant, t_end, progress),
                         solverType=exu.DynamicSolverType.GeneralizedAlpha)
        signals = _signals(mbs, model, sensors)
        window_start = min(variant.gearbox.load_case.ramp_time_s, 0.8 * t_end)
        if model.kinematics is not None:
            meta.update(elastic_share(mbs, model, sensors, window_start))
        for gear in model.joints:  # torque about the axis that each gear-shaft joint transmits
            torque = np.asarray(mbs.GetSensorStoredData(sensors[f"joint_{gear}"]))
            meta[f"joint_torque_{gear}_nm"] = float(torque[torque[:, 0] >= window_start, 3].mean())
        if not np.all(np.isfinite(signals.drop(columns="transmission_ratio").to_numpy())):
            raise FloatingPointError("the solution diverged (non-finite signals)")
        meta.update(status="ok", reason="", build_time_s=build_s)
    except Exception as exc:  # recorded, not raised: a failed variant must not stop a matrix
        signals = None
        meta.update(status="failed", reason=f"{type(exc).__name__}: {exc}",
                    traceback=traceback.format_exc(limit=5))
    meta.update(wall_time_s=time.perf_counter() - wall0, cpu_time_s=time.process_time() - cpu0)
    return RunResult(meta, signals)
