"""The run-result format shared by every backend (Exudyn multibody, lumped parameter).

A run directory holds ``run.json`` (metadata: variant, backend, status, configuration and its
hash, wall and CPU time, theory values, versions) and, for a finished run, ``signals.parquet``:
one row per recorded step, a ``time_s`` column and one column per signal, each named with its
unit (see :func:`signal_columns`); ``inputs/`` holds copies of the input files the run was made from.
Files are written atomically (:func:`flexgear.cache.atomic_write_bytes`: a hidden temporary file in the
same folder, then a rename), so a reader never sees a half-written result, even when the writer is killed;
:func:`flexgear.cache.remove_stale_temporaries` deletes what a killed writer left behind. Files are
readable by others (0644 under the usual umask 022; folders 0755).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from flexgear.cache import atomic_write_bytes

__all__ = ["RunResult", "signal_columns", "save_result", "load_result"]


def signal_columns(planet_count: int) -> list[str]:
    """Column names of the signal table, in order (units in the names).

    - ``time_s``
    - ``input_speed_deg_per_s``, ``output_speed_deg_per_s``: spin speeds of input and output shaft
    - ``transmission_ratio``: output / input speed
    - ``input_torque_nm``: drive torque on the input shaft
    - ``outer_mesh_force_{i}_n``: normal force of the sun-planet mesh of planet i (1-based)
    - ``inner_mesh_force_{i}_n``: normal force of the planet-ring mesh of planet i
    - ``{input,output}_bearing_accel_{x,y}_m_per_s2``: radial acceleration of the member carrying the input/output
      bearing, taken at its gear centre (the frame node of sun/ring or their shaft; the lumped model's node), not
      at the bearing seat

    Optional columns a backend may add after these (flexgear.mbs.deflection):

    - ``transmission_error_m``: loaded transmission error along the line of action at the output (rigid and
      elastic; positive when the output lags its kinematic position; its steady mean is the loaded static TE)
    - ``{outer,inner}_deflection_load_{i}_m``, ``{outer,inner}_deflection_centrifugal_{i}_m``: elastic
      deflection of the flexible gears of mesh i along the tooth normal, relative to each gear's bore or seat
      interface, load-induced and centrifugal parts (present when a gear of the mesh is flexible)
    """
    cols = ["time_s", "input_speed_deg_per_s", "output_speed_deg_per_s", "transmission_ratio", "input_torque_nm"]
    cols += [f"outer_mesh_force_{i}_n" for i in range(1, planet_count + 1)]
    cols += [f"inner_mesh_force_{i}_n" for i in range(1, planet_count + 1)]
    cols += [f"{s}_bearing_accel_{a}_m_per_s2" for s in ("input", "output") for a in ("x", "y")]
    return cols


@dataclass
class RunResult:
    """Signals (``None`` for a failed run) and metadata of one run."""

    meta: dict[str, Any]
    signals: pd.DataFrame | None = None
    extra: dict[str, pd.DataFrame] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.meta.get("status") == "ok"

    @property
    def name(self) -> str:
        return str(self.meta.get("variant", "?"))




def save_result(result: RunResult, run_dir: str | Path, inputs: dict[str, bytes] | None = None) -> Path:
    """Write ``inputs/<file>`` (copies of the input files), ``signals.parquet`` (if any), extra tables and
    then ``run.json`` into ``run_dir``: a run folder with a ``run.json`` is complete."""
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    if inputs:
        for name, data in inputs.items():
            atomic_write_bytes(run_dir / "inputs" / name, data)
        result.meta["inputs"] = {k: f"inputs/{k}" for k in inputs}
    if result.signals is not None:
        atomic_write_bytes(run_dir / "signals.parquet", result.signals.to_parquet(index=False))
    for name, table in result.extra.items():
        atomic_write_bytes(run_dir / f"{name}.parquet", table.to_parquet(index=False))
    meta = dict(result.meta, extra_tables=sorted(result.extra))
    atomic_write_bytes(run_dir / "run.json", json.dumps(meta, indent=2, default=str).encode())
    return run_dir


def load_result(run_dir: str | Path) -> RunResult:
    """Read a run directory written by :func:`save_result`."""
    run_dir = Path(run_dir)
    meta = json.loads((run_dir / "run.json").read_text())
    signals_path = run_dir / "signals.parquet"
    signals = pd.read_parquet(signals_path) if signals_path.exists() and meta.get("status") == "ok" else None
    extra = {n: pd.read_parquet(run_dir / f"{n}.parquet") for n in meta.get("extra_tables", [])}
    return RunResult(meta, signals, extra)


def package_versions(packages: tuple[str, ...] = ("flexgear", "exudyn", "numpy", "scipy", "numba", "ngsolve",
                                                  "pandas")) -> dict[str, str]:
    """Versions of Python and the packages a result depends on."""
    import platform
    from importlib import metadata

    out = {"python": platform.python_version()}
    for pkg in packages:
        try:
            out[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            out[pkg] = "not installed"
    return out


def run_metadata(name: str, backend: str, config_hash: str, t_end_s: float, load_case, planet_count: int,
                 components: dict[str, str], theory, **extra) -> dict:
    """The metadata block every backend writes beside its signals (``run.json``).

    ``load_case``: the spec's LoadCase (step and ramp times [s]); ``theory``: flexgear.theory.Theory of the
    same spec (the study's theoretical values, SI, speeds in deg/s only in the keys that say so).
    """
    import datetime as _dt

    return {
        "variant": name, "backend": backend, "config_hash": config_hash, "components": dict(components),
        "t_end_s": t_end_s, "step_size_s": load_case.step_size_s, "ramp_time_s": load_case.ramp_time_s,
        "planet_count": planet_count,
        "theory": {
            "input_speed_deg_per_s": theory.input_speed_deg_per_s,
            "output_speed_deg_per_s": theory.output_speed_deg_per_s,
            "ratio": theory.ratio, "input_torque_nm": theory.input_torque, "output_torque_nm": theory.output_torque,
            "mesh_force_n": theory.mesh_force, "mesh_frequency_hz": theory.mesh_frequency,
        },
        "versions": package_versions(),
        "created": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        **extra,
    }
