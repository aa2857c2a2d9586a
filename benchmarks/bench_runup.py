"""Run-up order map of a saved run against its variant's Campbell diagram: the strongest ridges and their predictions.

    python benchmarks/bench_runup.py [RUN_DIR] [VARIANT_FILE] [--frictionless]
                                                  (default: results/full/model1, model1.toml)

Prints, per bearing, the three strongest ridges (speed, order, prominence) with the matched crossing of the same
order (one the order excites, flexgear.modal.campbell_diagram: mesh phasing) and the ridge's error against it and
against the crossing's swept prediction under the run's own speed history and mesh load
(flexgear.study.runup.swept_peak);
then the matched mode linearised at the ridge's own operating point (its instantaneous speed and time t* in the
ramps of speed and load, flexgear.modal.linearize) and the crossing that mode makes there; then an interference
check: the ridge's complex order track A_k(t) (the demodulated sum before the modulus) over +-15 % of its speed
fitted by least squares as sum_j c_j a_j(t) + b_0 + b_1 (n - n_ridge) / n_ridge, a_j the swept single-mode tracks of
the excited crossings of the order (one per degenerate pair; complex c_j, b_0, b_1 free): the relative residual with
and without the matched mode (a weak mode on the others' off-resonant response peaks where their phases agree, not
at its own resonance: the fit holds it at its swept prediction); the nearest ridge of the same order in the
linearised model's own run-up, all modes together under the run's speed history and mesh load
(flexgear.study.runup_linear.linear_runup: at the load case's operating point, and along the ramp with the
load-dependent tangent stiffness), and that run-up's own strongest ridges; a summary of the three strongest ridges
of both bearings against it (the linear run-up's excitation includes tooth friction's first-order term,
flexgear.harmonic.friction); with --frictionless, the variant run again without tooth friction and its ridges
against the linear run-up of the same frictionless variant; and the CPU times.
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

from flexgear.modal import campbell, linearize, modes
from flexgear.results import load_result
from flexgear.spec import load_variant
from flexgear.study.runup import DEFAULT_HOP_S, DEFAULT_WINDOW_S, _blackman_harris, mesh_excitation, mesh_phase, runup
from flexgear.study.runup_linear import RAMP_POINTS, linear_runup, match_linear

ROOT = Path(__file__).resolve().parents[1]
PAIR_RTOL = 5e-3
"""Relative frequency spacing below which two crossings count as one degenerate pair (their tracks coincide)."""


def operating_point_crossing(variant, ridge, per_rpm: float) -> tuple[float, float]:
    """The matched mode's frequency [Hz] linearised at the ridge's speed and time, and its crossing [rpm] there."""
    m = modes(linearize(variant, speed_rpm=float(ridge["speed_rpm"]), t_star=float(ridge["time_s"])),
              2.0 * float(ridge["mode_hz"]))
    f = float(m.frequencies_hz[int(np.argmin(np.abs(m.frequencies_hz - ridge["mode_hz"])))])
    return f, f / (int(ridge["order"]) * per_rpm)


def complex_track(t: np.ndarray, y: np.ndarray, phase: np.ndarray, order: int) -> np.ndarray:
    """A_k(t) before the modulus (flexgear.study.runup.order_tracks) at every sample."""
    from scipy.signal import fftconvolve

    m = int(round(DEFAULT_WINDOW_S / (t[1] - t[0]))) | 1
    w = _blackman_harris(m)
    return 2.0 * fftconvolve(y * np.exp(-2j * np.pi * order * phase), w / w.sum(), mode="same")


def mode_track(t: np.ndarray, phase: np.ndarray, load: np.ndarray, order: int, f_hz: float, zeta: float) -> np.ndarray:
    """Complex track of one mode's acceleration under the run's mesh load (flexgear.study.runup.swept_peak)."""
    from scipy.signal import lsim

    w = 2.0 * np.pi * f_hz
    a = [[0.0, 1.0], [-w * w, -2.0 * zeta * w]]
    y = lsim((a, [[0.0], [1.0]], [[-w * w, -2.0 * zeta * w]], [[1.0]]), load * np.cos(2 * np.pi * order * phase),
             t - t[0])[1]
    return complex_track(t, y, phase, order)


def interference(result, side: str, ridge, crossings, per_rpm: float) -> tuple[float, float, int]:
    """(residual with, residual without the matched mode (and its degenerate partner), number of modes fitted)."""
    s = result.signals
    t, n = s["time_s"].to_numpy(), s["input_speed_rad_per_s"].to_numpy() * 30.0 / np.pi  # rpm
    phase, load, k = mesh_phase(t, n, per_rpm), mesh_excitation(s), int(ridge["order"])
    ramp = float(result.meta.get("ramp_time_s") or t[-1])
    hop = int(round(DEFAULT_HOP_S / (t[1] - t[0])))
    at = np.arange(0, t.size, hop)
    at = at[(np.abs(n[at] / ridge["speed_rpm"] - 1.0) <= 0.15) & (t[at] <= ramp)]
    z = complex_track(t, s[f"{side}_bearing_accel_x_m_per_s2"].to_numpy(), phase, k)[at]
    same = crossings[(crossings["order"] == k) & crossings["excited"] & (crossings["speed_rpm"] < n.max())]
    same = same.sort_values("frequency_hz")
    same = same[np.concatenate([[True], np.diff(same["frequency_hz"].to_numpy()) > PAIR_RTOL * same["frequency_hz"]
                                .to_numpy()[1:]])]  # one member of each degenerate pair: their tracks coincide
    tracks = {float(c["frequency_hz"]): mode_track(t, phase, load, k, c["frequency_hz"], c["damping_ratio"])[at]
              for _, c in same.iterrows()}
    x = (n[at] - ridge["speed_rpm"]) / ridge["speed_rpm"]

    def fit(modes: list[float]) -> tuple[float, np.ndarray]:
        a = np.stack([tracks[j] for j in modes] + [np.ones_like(x), x], axis=1)
        c, *_ = np.linalg.lstsq(a, z, rcond=None)
        return float(np.linalg.norm(a @ c - z) / np.linalg.norm(z)), a @ c

    with_it, _ = fit(list(tracks))
    without, _ = fit([f for f in tracks if abs(f / ridge["mode_hz"] - 1.0) > PAIR_RTOL])
    return with_it, without, len(tracks)


def main() -> None:
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    run_dir = Path(args[0]) if args else ROOT / "results" / "full" / "model1"
    variant = load_variant(args[1] if len(args) > 1 else ROOT / "model_variants" / "model1.toml")
    result = load_result(run_dir)
    t0 = time.process_time()
    c = campbell(variant, np.linspace(0.0, variant.gearbox.load_case.input_speed_rpm, 13))
    print(f"Campbell of {variant.name}, 13 speeds: {time.process_time() - t0:.1f} s CPU")
    t0 = time.process_time()
    linear = linear_runup(result, variant)
    print(f"linear run-up at the operating point ({linear.harmonics} mesh harmonics): "
          f"{time.process_time() - t0:.1f} s CPU")
    t0 = time.process_time()
    ramp = linear_runup(result, variant, along_ramp=True)
    print(f"linear run-up along the ramp ({RAMP_POINTS} linearisations): {time.process_time() - t0:.1f} s CPU")
    top = []
    for side in ("output", "input"):
        t0 = time.process_time()
        column = f"{side}_bearing_accel_x_m_per_s2"
        ru = runup(result, side, campbell=c)
        ru = dataclasses.replace(ru, ridges=match_linear(ru.ridges, linear.ridges[column]))
        on_ramp = match_linear(ru.ridges.head(3), ramp.ridges[column])
        print(f"{run_dir.name} {side} bearing: {time.process_time() - t0:.2f} s CPU, {len(ru.ridges)} ridges")
        for j, (_, r) in enumerate(ru.ridges.head(3).iterrows()):
            top.append((side, r, on_ramp.iloc[j]))
            print(f"  {r['order']:.0f}x ridge at {r['speed_rpm']:7.1f} rpm, t = {r['time_s']:.4f} s "
                  f"({r['prominence_db']:.1f} dB): crossing {r['crossing_rpm']:7.1f} rpm ({r['kind']}, "
                  f"{r['mode_hz']:.1f} Hz), error {r['error_pct']:+.2f} %; swept prediction "
                  f"{r['swept_rpm']:7.1f} rpm, error {r['swept_error_pct']:+.2f} %")
            print(f"      nearest {r['order']:.0f}x ridge of the linear run-up {r['linear_rpm']:7.1f} rpm, error "
                  f"{r['linear_error_pct']:+.2f} %; along the ramp {on_ramp.iloc[j]['linear_rpm']:7.1f} rpm, error "
                  f"{on_ramp.iloc[j]['linear_error_pct']:+.2f} %")
            if r["mode_hz"] == r["mode_hz"]:
                f, n_op = operating_point_crossing(variant, r, ru.map.mesh_hz_per_rpm)
                print(f"      mode at the ridge's operating point: {f:.2f} Hz, crossing {n_op:7.1f} rpm "
                      f"({100.0 * (n_op / r['crossing_rpm'] - 1.0):+.3f} % from the full-load crossing)")
                res, res0, count = interference(result, side, r, c.crossings, ru.map.mesh_hz_per_rpm)
                print(f"      complex track fitted by the {count} excited modes' swept tracks: residual "
                      f"{100 * res:.2f} % with the matched mode, {100 * res0:.1f} % without it")
        for name, lin in (("operating point", linear), ("along the ramp", ramp)):
            own = ", ".join(f"{q['order']:.0f}x {q['speed_rpm']:.1f} rpm ({q['prominence_db']:.1f} dB, "
                            f"{q['amplitude']:.3g} m/s^2)" for _, q in lin.ridges[column].head(3).iterrows())
            print(f"  linear run-up ({name}), its strongest ridges: {own or 'none'}")
    top.sort(key=lambda x: -x[1]["prominence_db"])
    print("the three strongest ridges against the linear run-up (operating point | along the ramp):")
    for side, r, q in top[:3]:
        print(f"  {side} {r['order']:.0f}x {r['speed_rpm']:7.1f} rpm ({r['prominence_db']:.1f} dB): "
              f"{r['linear_rpm']:7.1f} rpm {r['linear_error_pct']:+.2f} % | {q['linear_rpm']:7.1f} rpm "
              f"{q['linear_error_pct']:+.2f} %")
    within = sum(abs(r["linear_error_pct"]) <= 3.0 for _, r, _ in top[:3])
    print(f"  {within} of {min(3, len(top))} within 3 % of the linear run-up's ridges")
    if "--frictionless" in sys.argv:
        frictionless(variant)


def frictionless(variant) -> None:
    """The variant run again without tooth friction: its strongest ridges against the linear run-up of the same
    frictionless variant (no friction excitation)."""

    from flexgear.mbs.run import run_variant

    t0 = time.process_time()
    smooth = dataclasses.replace(variant, gearbox=variant.gearbox.with_fields("contact", friction_coefficient=0.0))
    free = run_variant(smooth)
    print(f"{variant.name} without tooth friction: {time.process_time() - t0:.1f} s CPU")
    linear = linear_runup(free, smooth)
    for side in ("output", "input"):
        column = f"{side}_bearing_accel_x_m_per_s2"
        for _, r in match_linear(runup(free, side).ridges, linear.ridges[column]).head(3).iterrows():
            print(f"  {side} {r['order']:.0f}x ridge at {r['speed_rpm']:7.1f} rpm ({r['prominence_db']:.1f} dB, "
                  f"{r['amplitude']:.3g} m/s^2): linear run-up {r['linear_rpm']:7.1f} rpm, error "
                  f"{r['linear_error_pct']:+.2f} %")


if __name__ == "__main__":
    main()
