"""Simulation (Exudyn backend): build a variant, integrate the load case, return a RunResult.

Solver: generalized-alpha (spectral radius from ``[solver_assumed]``), modified Newton with a
Jacobian update after at most ``newton_max_modified_iterations`` iterations, dense linear solver,
one thread, no solution file; sensors store every ``record_every_steps``-th step in memory.
"""

from __future__ import annotations

import math
import time
import traceback

import numpy as np
import pandas as pd

from flexgear.mbs.gearbox import GearboxModel, MassSource, ReducedSource, build_star_gearbox
from flexgear.mbs.recording import add_gearbox_sensors, simulation_settings
from flexgear.results import RunResult, run_metadata, signal_columns
from flexgear.spec import Variant, as_dict, spec_hash

__all__ = ["run_variant"]


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

    gb = variant.gearbox
    return run_metadata(variant.name, "exudyn", spec_hash(variant, t_end), t_end, gb.load_case,
                        gb.gears.planet_count, variant.components, theory(gb),
                        source=str(variant.source), spec=as_dict(gb))


def run_variant(variant: Variant, t_end_s: float | None = None, progress: bool = False,
                mass_source: MassSource | None = None, reduced_source: ReducedSource | None = None) -> RunResult:
    """Run ``variant`` for ``t_end_s`` (default: the load case's end time).

    Never raises for a model or solver failure: the result then has status "failed" and the reason.
    """
    import exudyn as exu
    from threadpoolctl import threadpool_limits

    t_end = variant.gearbox.load_case.end_time_s if t_end_s is None else float(t_end_s)
    meta = _meta(variant, t_end)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    # small BLAS calls only (mode-shape fits, post-processing): threads contend on a shared machine
    # (model 7's build: 6-7 s CPU with 2 OpenBLAS threads, 0.5-1.4 s with one; benchmarks/profile_mbs.py)
    blas = threadpool_limits(limits=1, user_api="blas")
    try:
        if not (t_end > 0 and math.isfinite(t_end)):
            raise ValueError(f"t_end_s must be a positive number, got {t_end_s!r}")
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        model = build_star_gearbox(mbs, variant, mass_source, reduced_source)
        sensors = add_gearbox_sensors(mbs, model)
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
    finally:
        blas.restore_original_limits()
    meta.update(wall_time_s=time.perf_counter() - wall0, cpu_time_s=time.process_time() - cpu0)
    return RunResult(meta, signals)
