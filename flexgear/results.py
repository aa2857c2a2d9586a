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

import numpy as np
import pandas as pd

from flexgear.cache import atomic_write_bytes

__all__ = ["RunResult", "SIGNAL_TYPES", "LEGACY_SPEED_COLUMNS", "signal_columns", "save_result", "load_result",
           "envelope"]

LEGACY_SPEED_COLUMNS = {"input_speed_deg_per_s": "input_speed_rad_per_s",
                        "output_speed_deg_per_s": "output_speed_rad_per_s"}
"""Speed columns (and ``theory`` keys) of results written before every signal took SI units: old name -> name now;
:func:`load_result` reads them as the new columns, converted from deg/s to rad/s."""

SIGNAL_TYPES: dict[str, tuple[str, str]] = {
    "input_speed": ("input speed", "speed [°/s]"),
    "output_speed": ("output speed", "speed [°/s]"),
    "outer_mesh_force": ("outer (sun-planet) mesh force, mean of the planets", "normal force [N]"),
    "inner_mesh_force": ("inner (planet-ring) mesh force, mean of the planets", "normal force [N]"),
    "input_bearing_accel": ("input-shaft bearing, radial acceleration √(a_x² + a_y²)", "acceleration [m/s²]"),
    "output_bearing_accel": ("output-shaft bearing, radial acceleration √(a_x² + a_y²)", "acceleration [m/s²]"),
    "transmission_error": ("transmission error", "TE [µm]"),
}
"""Signal types a run can plot (:meth:`RunResult.plot`): key -> (title, axis label with unit)."""


def signal_columns(planet_count: int, inner: bool = True) -> list[str]:
    """Column names of the signal table, in order (units in the names).

    - ``time_s``
    - ``input_speed_rad_per_s``, ``output_speed_rad_per_s``: spin speeds of input and output shaft
    - ``transmission_ratio``: output / input speed
    - ``input_torque_nm``: drive torque on the input shaft
    - ``outer_mesh_force_{i}_n``: normal force of the sun-planet mesh of planet i (1-based)
    - ``inner_mesh_force_{i}_n``: normal force of the planet-ring mesh of planet i (``inner``: the stage has a ring;
      not the parallel-axis pair, whose one planet is the wheel)
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
    cols = ["time_s", "input_speed_rad_per_s", "output_speed_rad_per_s", "transmission_ratio", "input_torque_nm"]
    cols += [f"outer_mesh_force_{i}_n" for i in range(1, planet_count + 1)]
    cols += [f"inner_mesh_force_{i}_n" for i in range(1, planet_count + 1) if inner]
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

    def has(self, kind: str) -> bool:
        """Whether the run recorded signal type ``kind`` (:data:`SIGNAL_TYPES`)."""
        if self.signals is None:
            return False
        if kind == "inner_mesh_force":  # none in the parallel-axis pair
            return "inner_mesh_force_1_n" in self.signals.columns
        return kind != "transmission_error" or "transmission_error_m" in self.signals.columns

    def signal(self, kind: str) -> np.ndarray:
        """One signal type over ``time_s`` in its plotting unit (:data:`SIGNAL_TYPES`)."""
        s = self.signals
        if s is None:
            raise ValueError(f"run {self.name!r} has no signals")
        if kind in ("input_speed", "output_speed"):
            return np.degrees(s[f"{kind}_rad_per_s"].to_numpy())
        if kind in ("outer_mesh_force", "inner_mesh_force"):
            mesh = kind.split("_")[0]
            return s[[c for c in s.columns if c.startswith(f"{mesh}_mesh_force_")]].to_numpy().mean(axis=1)
        if kind in ("input_bearing_accel", "output_bearing_accel"):
            side = kind.split("_")[0]
            return np.hypot(s[f"{side}_bearing_accel_x_m_per_s2"], s[f"{side}_bearing_accel_y_m_per_s2"]).to_numpy()
        if kind == "transmission_error":
            return s["transmission_error_m"].to_numpy() * 1e6
        raise ValueError(f"unknown signal type {kind!r}; allowed: {', '.join(SIGNAL_TYPES)}")

    def plot(self, ax, kind: str, zoom: tuple[float, float] | None = None, label: str | None = None,
             **style) -> None:
        """Draw signal type ``kind`` into matplotlib axes ``ax`` (min/max envelope of long signals),
        optionally only the time span ``zoom`` [s]; ``style``: matplotlib line properties."""
        t = self.signals["time_s"].to_numpy()
        y = self.signal(kind)
        if zoom is not None:
            keep = (t >= zoom[0]) & (t <= zoom[1])
            t, y = t[keep], y[keep]
        tt, yy = envelope(t, y)
        ax.plot(tt, yy, label=self.name if label is None else label, **{"lw": 0.8, **style})




def envelope(t: np.ndarray, y: np.ndarray, bins: int = 1500) -> tuple[np.ndarray, np.ndarray]:
    """Min/max envelope of a long signal for plotting (keeps the ripple's amplitude visible, drops points)."""
    n = len(t)
    if n <= 2 * bins:
        return t, y
    size = n // bins
    m = size * bins
    tb, yb = t[:m].reshape(bins, size), y[:m].reshape(bins, size)
    lo, hi = yb.argmin(axis=1), yb.argmax(axis=1)
    first, second = np.minimum(lo, hi), np.maximum(lo, hi)
    rows = np.arange(bins)
    tt = np.column_stack([tb[rows, first], tb[rows, second]]).ravel()
    yy = np.column_stack([yb[rows, first], yb[rows, second]]).ravel()
    return np.append(tt, t[m:]), np.append(yy, y[m:])


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
    """Read a run directory written by :func:`save_result` (speeds written in deg/s by earlier versions as the
    rad/s columns of :data:`LEGACY_SPEED_COLUMNS`)."""
    run_dir = Path(run_dir)
    meta = json.loads((run_dir / "run.json").read_text())
    signals_path = run_dir / "signals.parquet"
    signals = pd.read_parquet(signals_path) if signals_path.exists() and meta.get("status") == "ok" else None
    theory = meta.get("theory")
    for old, new in LEGACY_SPEED_COLUMNS.items():
        if signals is not None and old in signals.columns:
            signals = signals.rename(columns={old: new})
            signals[new] = np.radians(signals[new].to_numpy())
        if isinstance(theory, dict) and old in theory:
            theory[new] = float(np.radians(theory.pop(old)))
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
    same spec (the study's theoretical values, SI).
    """
    import datetime as _dt

    return {
        "variant": name, "backend": backend, "config_hash": config_hash, "components": dict(components),
        "t_end_s": t_end_s, "step_size_s": load_case.step_size_s, "ramp_time_s": load_case.ramp_time_s,
        "planet_count": planet_count,
        "theory": {
            "input_speed_rad_per_s": theory.input_speed, "output_speed_rad_per_s": theory.output_speed,
            "ratio": theory.ratio, "input_torque_nm": theory.input_torque, "output_torque_nm": theory.output_torque,
            "mesh_force_n": theory.mesh_force, "mesh_frequency_hz": theory.mesh_frequency,
        },
        "versions": package_versions(),
        "created": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        **extra,
    }
