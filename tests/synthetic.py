"""Synthetic run results with known inaccuracy and imprecision (for screening and report tests).

The window after the ramps is built from ``segments`` blocks of ``block`` recorded steps; on a
binary time step (2**-17 s) the block edges are exact floating-point numbers, so the screening's
segments coincide with the blocks. In block k an indicator equals

    theory * (1 + bias) + theory * cv * z_k + ripple,

with z_k a fixed zero-mean pattern of unit sample standard deviation and a ripple of whole
mesh cycles per block (zero mean in each block). So the Bias % is 100 |bias| and the CV % is
100 cv / |1 + bias|, exactly, by construction.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pandas as pd

from flexgear.results import RunResult, signal_columns
from flexgear.spec import load_gearbox
from flexgear.theory import theory

GEARBOX = str(Path(__file__).resolve().parents[1] / "model_variants" / "gearbox.toml")
DT = 2.0**-17
RAMP = 0.5
SEGMENTS = 10
BLOCK = 1310                          # steps per segment: 10 blocks = 0.09995 s after the ramp
PATTERN = np.array([1.0, -1.0, 0.5, -0.5, 2.0, -2.0, 0.0, 1.5, -1.5, 0.0])
PATTERN = PATTERN / np.std(PATTERN, ddof=1)          # mean 0, sample std 1
#: Table 7 (multibody) amplitudes at 1, 2, 4, 6, 9 x mesh frequency (input, output bearing)
TABLE7_MBD = {1: (0.0549, 0.0590), 2: (0.0020, 0.0008), 4: (0.0126, 0.0014), 6: (0.0094, 0.0015),
              9: (0.0017, 0.0013)}


def theory_meta() -> dict:
    th = theory(load_gearbox(GEARBOX))
    return {"input_speed_rad_per_s": th.input_speed, "output_speed_rad_per_s": th.output_speed,
            "ratio": th.ratio, "input_torque_nm": th.input_torque, "output_torque_nm": th.output_torque,
            "mesh_force_n": th.mesh_force, "mesh_frequency_hz": th.mesh_frequency}


def _blocks(value: float, bias: float, cv: float, n_window: int) -> np.ndarray:
    seg = np.minimum(np.arange(n_window) // BLOCK, SEGMENTS - 1)
    return value * (1.0 + bias) + value * cv * PATTERN[seg]


def synthetic_result(name: str, bias: dict[str, float] | None = None, cv: dict[str, float] | None = None,
                     wall_time_s: float = 1.0, t_start: float = 0.4, planets: int = 5) -> RunResult:
    """A finished run whose indicators have the given relative bias and CV (fractions, not %)."""
    bias, cv = bias or {}, cv or {}
    th = theory_meta()
    n_pre = round((RAMP - t_start) / DT)
    n_win = SEGMENTS * BLOCK + 1                      # the end point joins the last segment
    t = RAMP + (np.arange(-n_pre, n_win) * DT)
    n = len(t)
    loc = np.arange(-n_pre, n_win) % BLOCK
    ripple = np.sin(2.0 * np.pi * 3.0 * loc / BLOCK)   # 3 whole cycles per block

    def indicator(key: str, value: float) -> np.ndarray:
        y = np.full(n, value)
        y[n_pre:] = _blocks(value, bias.get(key, 0.0), cv.get(key, 0.0), n_win)
        return y

    cols = signal_columns(planets)
    data = {"time_s": t,
            "input_speed_rad_per_s": indicator("input_speed", th["input_speed_rad_per_s"]),
            "output_speed_rad_per_s": indicator("output_speed", th["output_speed_rad_per_s"]),
            "transmission_ratio": indicator("transmission_ratio", th["ratio"]),
            "input_torque_nm": np.full(n, th["input_torque_nm"])}
    for mesh in ("outer", "inner"):
        base = indicator(f"{mesh}_mesh_force", th["mesh_force_n"])
        offsets = np.linspace(-4.0, 4.0, planets)     # planet-to-planet spread, zero mean
        for i in range(planets):
            data[f"{mesh}_mesh_force_{i + 1}_n"] = base + offsets[i] + 5.0 * ripple
    fm = th["mesh_frequency_hz"]
    for j, side in enumerate(("input", "output")):
        for phase, axis in ((0.0, "x"), (np.pi / 2, "y")):
            data[f"{side}_bearing_accel_{axis}_m_per_s2"] = sum(
                amp[j] * np.cos(2 * np.pi * k * fm * t + phase) for k, amp in TABLE7_MBD.items())
    meta = {"variant": name, "backend": "exudyn", "status": "ok", "reason": None, "config_hash": f"hash-{name}",
            "wall_time_s": wall_time_s, "cpu_time_s": wall_time_s, "t_end_s": float(t[-1]), "step_size_s": DT,
            "ramp_time_s": RAMP, "planet_count": planets, "theory": th,
            "components": {c: "rigid" for c in ("input_shaft", "sun", "planets", "ring", "output_shaft")},
            "versions": {"flexgear": "test"}, "created": "2026-01-01T00:00:00"}
    return RunResult(meta, pd.DataFrame(data)[cols])


def failed_result(name: str, reason: str = "diverged") -> RunResult:
    return RunResult({"variant": name, "backend": "exudyn", "status": "failed", "reason": reason,
                      "theory": theory_meta(), "wall_time_s": 0.5})


def fake_runner(variant, t_end_s: float | None = None, progress: bool = False, error_window_s: float = 0.0
                ) -> RunResult:
    """Stand-in for flexgear.mbs.run.run_variant (picklable, importable by worker processes); a screening
    reference's ``error_window_s`` is accepted and ignored (no numerical error windows: the errors are nan).

    More flexible components give a smaller bias and a longer time, as in the study. A variant
    named "boom" raises like a failing solver, "crash" kills its worker process, and "diverge"
    returns a failed result. One whose name starts with "slow" writes its process id to
    ``$FLEXGEAR_TEST_PID_DIR/<name>.pid`` and sleeps ``$FLEXGEAR_TEST_SLOW_S`` seconds (for kill tests).
    Every result records the worker's working directory and cache folder.
    """
    if variant.name.startswith("slow"):
        pid_dir = os.environ.get("FLEXGEAR_TEST_PID_DIR")
        if pid_dir:
            with open(os.path.join(pid_dir, f"{variant.name}.pid"), "a") as fh:
                fh.write(f"{os.getpid()}\n")
        time.sleep(float(os.environ.get("FLEXGEAR_TEST_SLOW_S", "0")))
    if variant.name == "boom":
        raise RuntimeError("solver blew up")
    if variant.name == "crash":
        os._exit(3)                                   # a worker process dying (segfault, OOM kill)
    if variant.name == "diverge":
        return failed_result(variant.name, "FloatingPointError: the solution diverged")
    flex = sum(v == "flexible" for v in variant.components.values())
    keys = ("output_speed", "outer_mesh_force", "inner_mesh_force")
    res = synthetic_result(variant.name, dict.fromkeys(keys, 0.01 / (1 + flex)), dict.fromkeys(keys, 0.002),
                           wall_time_s=1.0 + flex)
    res.meta.update(components=dict(variant.components), t_end_s=t_end_s, worker_cwd=os.getcwd(),
                    worker_cache=os.environ.get("FLEXGEAR_CACHE_DIR", ""))
    return res


def slow_runner(variant, t_end_s: float | None = None, progress: bool = False) -> RunResult:
    """:func:`fake_runner` that takes 1.5 s per run (time to kill a sweep between two runs)."""
    import time

    time.sleep(1.5)
    return fake_runner(variant, t_end_s, progress)
