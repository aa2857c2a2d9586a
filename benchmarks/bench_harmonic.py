"""How long does the harmonic response of model 7 take over 200 speeds x 10 harmonics against one 0.1 s time-domain
run of model 7, and does the frequency domain match settled time integration of models 1 and 7 at three speeds?

Run: nice -n 5 python benchmarks/bench_harmonic.py speed [--repeat 1] [--speeds 200] [--harmonics 10]
     nice -n 5 python benchmarks/bench_harmonic.py checks [model_variants/model1.toml model_variants/model7.toml]
                                                           [--lumped-only | --no-lumped] [--gearbox FILE]
                                                           [--linearization spin] [--angles J] [--window-angles M]
                                                           [--save DIR | --signals DIR]

- ``speed``: caches warmed first (a linearisation loads the reduced bodies, a 1e-4 s run compiles the time model);
  then per round, interleaved, flexgear.harmonic.harmonic_response of model 7 over ``--speeds`` speeds from 500 to
  7000 rpm x ``--harmonics`` harmonics (the default: two linearisations, the spin fit and the modal solve) and
  flexgear.mbs.run.run_variant of model 7 to 0.1 s (the build included, as a run reports it); wall and CPU time,
  medians and the ratio. Then the modal solve against the dense solve of all coordinates at every tenth speed and
  the highest (the grid's highest speed sets the linearisations' gear angles and modes): the largest difference
  of each indicator family relative to that family's largest amplitude per harmonic.
- ``checks``: each variant under the ISO 6336 law without friction (the linearisation's scope), its own number of
  stiffness harmonics. The response over 500-7000 rpm locates the peaks of K_v - 1; the first whose height is at
  least :data:`STRONG` of the highest is the first strong crossing n_c. At n_c x :data:`BESIDE` (below, on, above)
  the frequency domain over the turning angle (flexgear.harmonic.turning_response: for a flexible ring or output
  shaft, J operating points a whole number of mesh cycles apart at the pattern phases j / J of the 12 bolts turning
  at f_ring; without one, flexgear.harmonic.harmonic_response) against a settled time run (ramps over
  :data:`RAMP_S`, then until the settling test passes; or its signals read back with ``--signals DIR``, the
  settling test redone on them). Compared: the 1x and 2x amplitudes of the mesh forces of planet 1 and the four
  bearing accelerations, the angle RMS (all sidebands, flexgear.harmonic.turning eq. 1) against the
  root-sum-square of the lines at h f_mesh + p B f_ring, |p| <= (J - 1) / 2, over the settled part (whole mesh
  cycles; flexgear.study.harmonic_check.sideband_rss; P = 0, the line at exactly h f_mesh, without a pattern);
  and K_v, the quasi-static peak over the angles (eq. 2) against the time window's peak over mean mesh force
  (the last :data:`WINDOW_S`, flexgear.study.indicators). Relative differences, goal 10 %; "halves": the time
  value's change from the first half of the settled part to the second; "moved": K_v's from the window before the
  last. An amplitude below :data:`CANCELLED` of its family's largest at that speed in the frequency domain is
  shown but not judged. Shown beside, not judged: the frequency domain at the first angle alone, the former 0.05 s
  window's Hann-windowed DTFT, the line at exactly h f_mesh, for a pattern the 2x bearing accelerations' sidebands
  p = -2..2 in both domains, K_v - 1 of the window's mesh-periodic part and the static forces' swing over the
  angles. With ``--window-angles M`` K_v is judged as eq. 2 over M operating points spread over the time run's K_v
  window instead: every gear at its angle in the run, so that the quasi-static load sharing of all turning bodies
  (sun and planets besides the ring's bolts, at incommensurate rates) is that of the angles the window passes
  through; a peak over a finite window depends on which angle combinations it visits, and the two domains are then
  compared over the same ones. ``--save DIR`` keeps each time run's signals.
  Then the lumped model of ``--gearbox`` under the same law against its own settled time integration
  (flexgear.study.harmonic_check: the same rule for the first strong peak, its crossing read off the lumped model's
  Campbell diagram through the mode that carries the peak, the three speeds n_c x BESIDE, runs to settle_max_time_s
  with the settling test, the same amplitudes and K_v; "moved": the time value's change from the window before the
  last), and its peaks of the 1x and 2x curves on a :data:`PEAK_STEP_RPM` grid against the Campbell crossings of
  the modes that carry them (flexgear.harmonic.peaks.peak_crossings), goal 1 %.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from bench_speed import load_average  # noqa: E402

from flexgear.harmonic import harmonic_response, mesh_frequency_hz  # noqa: E402
from flexgear.spec import load_variant  # noqa: E402

STRONG = 0.5
"""A peak of K_v - 1 at least this fraction of the highest counts as a strong crossing."""
BESIDE = (0.75, 1.0, 1.25)
"""The three check speeds as multiples of the first strong crossing's speed."""
RAMP_S, END_S, WINDOW_S = 0.05, 0.25, 0.05
"""Time runs: ramps of speed and load [s], the load case's end before the settling test [s], the analysed window."""
CANCELLED = 0.01
"""Amplitudes below this fraction of their family's largest (frequency domain, same speed) are not judged."""
PEAK_STEP_RPM = 5.0
"""Step of the lumped model's peak grid [rpm]: a grid point within 0.2 % of its lowest crossing's speed."""
PEAK_INDICATORS = ("outer_mesh_force_1_n", "inner_mesh_force_1_n", "input_bearing_accel_x_m_per_s2",
                   "output_bearing_accel_x_m_per_s2")
COLUMNS = ("outer_mesh_force_1_n", "inner_mesh_force_1_n", "input_bearing_accel_x_m_per_s2",
           "input_bearing_accel_y_m_per_s2", "output_bearing_accel_x_m_per_s2", "output_bearing_accel_y_m_per_s2")


def _iso_spec(spec):
    spec = spec.with_fields("contact", law="iso6336", friction_coefficient=0.0)
    return spec.with_fields("contact_assumed", stiffness_variation="contact_lines")


def _iso(variant):
    return dataclasses.replace(variant, gearbox=_iso_spec(variant.gearbox))


def speed(a: argparse.Namespace) -> None:
    from flexgear.mbs.run import run_variant
    from flexgear.modal.linear import linearize

    variant = load_variant(ROOT / "model_variants" / "model7.toml")
    speeds = np.linspace(500.0, 7000.0, a.speeds)
    print(load_average())
    t0 = time.perf_counter()
    linearize(variant, speed_rpm=7000.0)
    run_variant(variant, t_end_s=1e-4)
    print(f"warm-up (reduced bodies, compiled kernels): {time.perf_counter() - t0:.1f} s")
    sweep, run = {"wall": [], "cpu": []}, {"wall": [], "cpu": []}
    response = None
    for _ in range(a.repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        response = harmonic_response(variant, speeds, a.harmonics)
        sweep["wall"].append(time.perf_counter() - w0)
        sweep["cpu"].append(time.process_time() - c0)
        w0, c0 = time.perf_counter(), time.process_time()
        result = run_variant(variant, t_end_s=0.1)
        run["wall"].append(time.perf_counter() - w0)
        run["cpu"].append(time.process_time() - c0)
        assert result.ok, result.meta.get("reason")
    med = {k: {q: statistics.median(v) for q, v in d.items()} for k, d in (("sweep", sweep), ("run", run))}
    print(f"harmonic response, {a.speeds} speeds x {a.harmonics} harmonics: wall {sweep['wall']} s, CPU "
          f"{sweep['cpu']} s")
    print(f"time run of model 7 to 0.1 s: wall {run['wall']} s, CPU {run['cpu']} s")
    print(f"ratio sweep / run (medians): wall {med['sweep']['wall'] / med['run']['wall']:.3f}, CPU "
          f"{med['sweep']['cpu'] / med['run']['cpu']:.3f}")
    print(load_average())
    sub = np.unique(np.append(speeds[::10], speeds[-1]))  # with the highest: the same linearisations
    t0 = time.perf_counter()
    dense = harmonic_response(variant, sub, a.harmonics, modal_cutoff_ratio=None)
    print(f"dense solve at {sub.size} speeds: {time.perf_counter() - t0:.1f} s; modal against dense, largest "
          "difference / the family's largest amplitude, per harmonic:")
    for family, names in (("mesh forces", [n for n in response.indicators if "mesh_force" in n]),
                          ("bearing accelerations", [n for n in response.indicators if "accel" in n]),
                          ("transmission error", ["transmission_error_m"])):
        err = np.zeros(a.harmonics)
        for name in names:
            ref = dense.complex(name).to_numpy()
            got = response.complex(name).loc[sub].to_numpy()
            err = np.maximum(err, np.abs(got - ref).max(axis=0) / np.abs(ref).max(axis=0).clip(1e-300))
        print(f"  {family}: max {err.max():.2e}; per harmonic {' '.join(f'{e:.1e}' for e in err)}")
    kv_d = dense.dynamic_factor().to_numpy()
    kv_m = response.dynamic_factor().loc[sub].to_numpy()
    print(f"  K_v - 1: largest relative difference {np.max(np.abs(kv_m - kv_d) / (kv_d - 1.0)):.2e}")


def _strong_crossing(response) -> float:
    kv = response.dynamic_factor()
    n, y = kv.index.to_numpy(), kv.to_numpy() - 1.0
    inner = np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:])) + 1
    if not inner.size:
        raise RuntimeError("no peak of K_v in the range")
    strong = inner[y[inner] >= STRONG * y[inner].max()]
    return float(n[strong[0]])


def _time_signals(a: argparse.Namespace, run, n: float, f_mesh: float):
    """(signals, start of the settled part [s], how obtained) of the settled time run of ``run`` at ``n`` [rpm]:
    run now (flexgear.mbs.run.run_variant to "settled") or read from ``--signals DIR`` (the settling test of the
    run, flexgear.settling.settled_start, on the whole saved signals)."""
    if a.signals:
        import pandas as pd

        from flexgear.settling import SettleRule, settled_start

        path = Path(a.signals) / f"{run.name}_{n:g}rpm.parquet"
        sig = pd.read_parquet(path)
        screening = run.gearbox.screening
        test = settled_start(sig, RAMP_S + screening.after_ramp_delay_s, f_mesh, SettleRule.from_settings(screening))
        if not test.settled:
            raise RuntimeError(f"{path}: {test.reason}")
        return sig, float(test.start_s), f"read {path.name}"
    from flexgear.mbs.run import run_variant

    t0 = time.perf_counter()
    result = run_variant(run, t_end_s="settled")
    assert result.ok, result.meta.get("reason")
    if not result.meta.get("settled"):
        raise RuntimeError(f"{run.name} at {n:g} rpm: {result.meta.get('settle_reason')}")
    if a.save:
        Path(a.save).mkdir(parents=True, exist_ok=True)
        result.signals.to_parquet(Path(a.save) / f"{run.name}_{n:g}rpm.parquet")
    return result.signals, float(result.meta["settled_at_s"]), f"time run {time.perf_counter() - t0:.0f} s"


def _family_scale(freq, column: str, n: float) -> float:
    family = [c for c in COLUMNS if ("accel" in c) == ("accel" in column)]
    return max(freq.amplitudes(c).loc[n].to_numpy()[:2].max() for c in family)


def checks(a: argparse.Namespace) -> None:
    from flexgear.harmonic import turning_pattern, turning_response
    from flexgear.study.compare import harmonic_amplitudes
    from flexgear.study.harmonic_check import line_amplitude, periodic_peak_factor, sideband_rss
    from flexgear.study.indicators import dynamic_factor

    print(load_average())
    worst, judged_all = 0.0, []
    for path in [] if a.lumped_only else a.variants:
        variant = _iso(load_variant(path))
        spec = variant.gearbox
        harmonics = spec.contact_assumed.stiffness_harmonics
        pattern = turning_pattern(variant)
        t0 = time.perf_counter()
        response = harmonic_response(variant, np.arange(500.0, 7000.0 + 1.0, 25.0), harmonics)
        crossing = _strong_crossing(response)
        print(f"\n{variant.name}: response 500-7000 rpm in {time.perf_counter() - t0:.1f} s; first strong peak of "
              f"K_v at {crossing:g} rpm (K_v {response.dynamic_factor().loc[crossing]:.4f}); turning pattern: "
              + ("none (one angle)" if pattern is None else
                 f"{'+'.join(pattern.components)}, {pattern.order}-fold"))
        for factor in BESIDE:
            n = round(crossing * factor, 1)
            t0 = time.perf_counter()
            freq = turning_response(variant, [n], harmonics, angles=a.angles, linearization=a.linearization)
            t_freq = time.perf_counter() - t0
            lc = dict(input_speed_rpm=n, ramp_time_s=RAMP_S, end_time_s=END_S)
            run = dataclasses.replace(variant, gearbox=spec.with_fields("load_case", **lc))
            f_mesh = mesh_frequency_hz(spec, n)
            sig, start, how = _time_signals(a, run, n, f_mesh)
            t = sig["time_s"].to_numpy()
            dt = float(t[-1] - t[-2])  # the recorded step (a run may start with shorter ones)
            k = int(round(math.floor(WINDOW_S * f_mesh) / f_mesh / dt))
            long = int(round(math.floor((t[-1] - start) * f_mesh) / f_mesh / dt))  # the settled part, whole cycles
            if not np.allclose(np.diff(t[-long - 1:]), dt, rtol=1e-6):
                raise RuntimeError("the settled part is not uniformly sampled")
            order = 0 if pattern is None else freq.sideband_order
            spacing = 0.0 if pattern is None else 1.0 / pattern.period_s(n)
            print(f"  {n:g} rpm ({factor:g} x): frequency domain at {freq.count} angle(s) {t_freq:.0f} s; {how}, "
                  f"settled at {start:.4f} s, settled part {long * dt:.3f} s (resolution {1.0 / (long * dt):.1f} Hz)"
                  + ("" if pattern is None else f"; lines h f_mesh + p {pattern.order} f_ring, |p| <= {order}, "
                     f"{pattern.order} f_ring = {spacing:.1f} Hz"))
            for column in COLUMNS:
                fd = freq.amplitudes(column).loc[n].to_numpy()[:2]
                one = np.abs(freq.angles[n][0].complex(column).iloc[0].to_numpy()[:2])
                scale = _family_scale(freq, column, n)
                x = sig[column].to_numpy()[-long:]
                window = harmonic_amplitudes(x[-k:], dt, f_mesh, (1, 2))  # the former time value
                half = long // 2
                cells = []
                for h in (1, 2):
                    td = sideband_rss(x, dt, h * f_mesh, spacing, order)
                    parts = [sideband_rss(y, dt, h * f_mesh, spacing, order) for y in (x[:half], x[half:])]
                    rel = fd[h - 1] / td - 1.0
                    judged = fd[h - 1] >= CANCELLED * scale
                    if judged:
                        worst = max(worst, abs(rel))
                        judged_all.append(rel)
                    line = line_amplitude(x, dt, h * f_mesh)
                    cells.append(f"{h}x freq {fd[h - 1]:.4g} time {td:.4g} ({100 * rel:+.1f} %"
                                 f"{'' if judged else ', below CANCELLED: not judged'}; halves "
                                 f"{100 * (parts[1] / parts[0] - 1.0):+.1f} %) [one angle {one[h - 1]:.4g}; "
                                 f"{WINDOW_S:g} s window {window[h - 1]:.4g}; line at {h} f_mesh {line:.3g}]")
                print(f"    {column}: " + "; ".join(cells))
                if pattern is not None and "accel" in column:
                    sb = freq.sidebands(column, n, 2)
                    print("      2x sidebands p -2..2, freq / time: " + ", ".join(
                        f"{p:+d}: {sb.loc[p]:.3g} / {line_amplitude(x, dt, 2 * f_mesh + p * spacing):.3g}"
                        for p in range(-2, 3) if p in sb.index))
            planets = spec.gears.planet_count
            forces = [np.stack([sig[f"{kind}_mesh_force_{i + 1}_n"].to_numpy() for i in range(planets)], axis=1)
                      for kind in ("outer", "inner")]
            kv_t = dynamic_factor(*(f[-k:] for f in forces))
            kv_b = dynamic_factor(*(f[-2 * k:-k] for f in forces))
            kv_f = float(freq.dynamic_factor().loc[n])
            kv_1 = float(freq.angles[n][0].dynamic_factor().iloc[0])
            rel = (kv_f - 1.0) / (kv_t - 1.0) - 1.0
            kv_w = _window_kv(run, n, harmonics, t[-k], t[-1], a.window_angles) if a.window_angles else None
            if kv_w is not None:  # judged over the gear angles the time window passes through (module docstring)
                rel_w = (kv_w[0] - 1.0) / (kv_t - 1.0) - 1.0
                worst = max(worst, abs(rel_w))
                judged_all.append(rel_w)
            else:
                worst = max(worst, abs(rel))
                judged_all.append(rel)
            print(f"    K_v - 1: freq {kv_f - 1:.4g} time {kv_t - 1:.4g} ({100 * rel:+.1f} %"
                  f"{'' if kv_w is None else ', not judged'}; moved "
                  f"{100 * ((kv_t - 1.0) / (kv_b - 1.0) - 1.0):+.1f} %) [one angle {kv_1 - 1:.4g}]")
            if kv_w is not None:
                print(f"      over the window's gear angles ({a.window_angles} points, {kv_w[1]:.0f} s): K_v - 1 "
                      f"{kv_w[0] - 1:.4g} ({100 * rel_w:+.1f} % from the time domain; judged)")
            kv_p = periodic_peak_factor(np.hstack([f[-k:] for f in forces]), dt, f_mesh, harmonics)
            static = freq.static_forces_n(n)
            swing = float((static / static.mean() - 1.0).abs().to_numpy().max())
            print(f"      the window's mesh-periodic part: K_v - 1 {kv_p - 1:.4g}; the rest {kv_t - kv_p:+.4g} of the "
                  f"mean force; static mesh forces over the angles: largest |F_s / mean - 1| {swing:.3g}")
    if not a.lumped_only:
        print(f"\njudged differences: {len(judged_all)}, within 10 %: {sum(abs(r) <= 0.1 for r in judged_all)}; "
              f"largest {100 * worst:.1f} % (goal 10 %)")
    if not a.no_lumped:
        lumped_checks(a.gearbox)
    print(load_average())


def _window_kv(run, n: float, harmonics: int, t_a: float, t_b: float, count: int) -> tuple[float, float]:
    """Eq. 2 of flexgear.harmonic.turning over ``count`` operating points t* spread over the time run's K_v window
    [t_a, t_b] [s] (every gear at its angle in the run, the run's ramps): the quasi-static peak over the gear angles
    the window passes through, all turning bodies together. Returns (K_v, wall time [s])."""
    from flexgear.harmonic.turning import TurningResponse
    from flexgear.modal.linear import linearize

    t0 = time.perf_counter()
    points = [harmonic_response(linearize(run, speed_rpm=n, t_star=float(ts), cutoff_rpm=n), [n], harmonics)
              for ts in np.linspace(t_a, t_b, count)]
    kv = float(TurningResponse({n: points}, None, run.name).dynamic_factor().loc[n])
    return kv, time.perf_counter() - t0


def lumped_checks(path: str) -> None:
    """The lumped model's checks (module docstring)."""
    from flexgear.harmonic.peaks import peak_crossings
    from flexgear.spec import load_gearbox
    from flexgear.study.harmonic_check import check_speeds, compare_lumped

    spec = _iso_spec(load_gearbox(path))
    t0 = time.perf_counter()
    cs = check_speeds(spec, beside=BESIDE, strong=STRONG)
    print(f"\nlumped model ({Path(path).name}): first strong peak of K_v at {cs.peak_rpm:g} rpm (K_v {cs.kv:.4f}), "
          f"set by {cs.mesh} at {cs.order}x, carried by the mode at {cs.frequency_hz:.1f} Hz (damping ratio "
          f"{cs.damping_ratio:.3f}, share {cs.share:.2f}); its Campbell crossing with {cs.order}x at "
          f"{cs.crossing_rpm:.1f} rpm ({time.perf_counter() - t0:.1f} s)")
    worst = 0.0
    for factor, n in zip(BESIDE, cs.speeds_rpm, strict=True):
        check = compare_lumped(spec, n)
        worst = max(worst, check.worst)
        print(f"  {n:g} rpm ({factor:g} x): time run {check.wall_time_s:.1f} s; {check.settling.reason}; window "
              f"{check.window_s[0]:.4f}-{check.window_s[1]:.4f} s")
        for _, r in check.table.iterrows():
            what = "K_v - 1" if r.harmonic == 0 else f"{r.quantity} {r.harmonic}x"
            print(f"    {what}: freq {r.frequency:.4g} time {r.time:.4g} ({100 * r.difference:+.1f} %"
                  f"{'' if r.judged else ', cancelled: not judged'}); moved {100 * r.moved:+.1e} %")
    print(f"  lumped model, largest judged difference: {100 * worst:.1f} % (goal 10 %)")
    t0 = time.perf_counter()
    grid = np.arange(500.0, 7000.0 + 0.5 * PEAK_STEP_RPM, PEAK_STEP_RPM)
    peaks = peak_crossings(spec, grid, PEAK_INDICATORS, orders=(1, 2),
                           harmonics=spec.contact_assumed.stiffness_harmonics)
    print(f"\nlumped model: peaks of the 1x and 2x curves over {grid.size} speeds against the Campbell crossings of "
          f"the modes that carry them ({time.perf_counter() - t0:.1f} s):")
    for _, p in peaks.iterrows():
        print(f"  {p.indicator} {p.harmonic}x: peak {p.peak_rpm:.1f} rpm, mode {p.frequency_hz:.1f} Hz {p.kind} "
              f"(damping ratio {p.damping_ratio:.3f}, share {p.share:.2f}), crossing {p.crossing_rpm:.1f} rpm: "
              f"{100 * p.difference:+.2f} %")
    print(f"  largest |difference| {100 * peaks.difference.abs().max():.2f} % (goal 1 %); within 1 %: "
          f"{int((peaks.difference.abs() <= 0.01).sum())} of {len(peaks)}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="section", required=True)
    s = sub.add_parser("speed")
    s.add_argument("--repeat", type=int, default=1)
    s.add_argument("--speeds", type=int, default=200)
    s.add_argument("--harmonics", type=int, default=10)
    c = sub.add_parser("checks")
    c.add_argument("variants", nargs="*", default=[str(ROOT / "model_variants" / f"model{i}.toml") for i in (1, 7)])
    only = c.add_mutually_exclusive_group()
    only.add_argument("--lumped-only", action="store_true", help="the lumped model's checks only")
    only.add_argument("--no-lumped", action="store_true", help="without the lumped model's checks")
    c.add_argument("--linearization", default="spin", choices=("spin", "quadratic", "each"),
                   help="the linearisation at each check speed of a variant without a turning pattern "
                        "(flexgear.harmonic.harmonic_response; with one: one linearisation per angle; the sweep that "
                        "locates the crossing: spin)")
    c.add_argument("--angles", type=int, default=None,
                   help="angles J per period of a turning pattern (flexgear.harmonic.turning; default 2 P + 1)")
    c.add_argument("--window-angles", type=int, default=0,
                   help="diagnostic: the quasi-static K_v over this many gear angles of the time run's K_v window")
    io = c.add_mutually_exclusive_group()
    io.add_argument("--save", default=None, help="directory: each time run's signals as <model>_<speed>rpm.parquet")
    io.add_argument("--signals", default=None,
                    help="directory of saved signals (<model>_<speed>rpm.parquet) to read instead of running")
    c.add_argument("--gearbox", default=str(ROOT / "model_variants" / "gearbox.toml"),
                   help="gearbox file of the lumped model's checks")
    a = ap.parse_args()
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    {"speed": speed, "checks": checks}[a.section](a)


if __name__ == "__main__":
    main()
