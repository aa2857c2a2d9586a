"""How long does the harmonic response of model 7 take over 200 speeds x 10 harmonics against one 0.1 s time-domain
run of model 7, and does the frequency domain match settled time integration of models 1 and 7 at three speeds?

Run: nice -n 5 python benchmarks/bench_harmonic.py speed [--repeat 1] [--speeds 200] [--harmonics 10]
     nice -n 5 python benchmarks/bench_harmonic.py checks [model_variants/model1.toml model_variants/model7.toml]
                                                           [--lumped-only | --no-lumped] [--gearbox FILE]
                                                           [--linearization spin] [--angles M] [--save DIR]

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
  a settled time run (ramps over :data:`RAMP_S`, then until the settling test passes) gives the 1x and 2x mesh
  amplitudes (windowed DTFT over the last :data:`WINDOW_S`, whole mesh cycles) of the mesh forces of planet 1 and
  the four bearing accelerations, and K_v (peak over mean mesh force, flexgear.study.indicators), against the
  frequency domain at the same speed: relative differences, goal 10 %; "moved": the time value's change from the
  window before the last. An amplitude the planets' phasing cancels (below :data:`CANCELLED` of its family's
  largest at that speed in the frequency domain) is shown but not judged. Diagnostics, not judged
  (flexgear.study.harmonic_check): over the whole settled part (resolution its inverse length) the lines at exactly
  1x and 2x mesh and at 2 f_mesh -/+ B f_ring (B the ring's bolts, f_ring its rotation), which a rotating member
  with a B-fold pattern adds and the 0.05 s window cannot tell from 2x; K_v - 1 of the window's mesh-periodic part
  (what the frequency domain computes); with ``--angles M`` the frequency domain linearised at M gear angles over
  one ring revolution (K_v - 1 over the angles; the 2x bearing accelerations' complex mean, which the time
  domain's line at exactly 2 f_mesh corresponds to, and RMS). ``--save DIR`` keeps each time run's signals.
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


def checks(a: argparse.Namespace) -> None:
    from flexgear.mbs.run import run_variant
    from flexgear.study.compare import harmonic_amplitudes
    from flexgear.study.harmonic_check import line_amplitude, periodic_peak_factor
    from flexgear.study.indicators import _kv

    print(load_average())
    worst = 0.0
    for path in [] if a.lumped_only else a.variants:
        variant = _iso(load_variant(path))
        spec = variant.gearbox
        harmonics = spec.contact_assumed.stiffness_harmonics
        t0 = time.perf_counter()
        response = harmonic_response(variant, np.arange(500.0, 7000.0 + 1.0, 25.0), harmonics)
        crossing = _strong_crossing(response)
        print(f"\n{variant.name}: response 500-7000 rpm in {time.perf_counter() - t0:.1f} s; first strong peak of "
              f"K_v at {crossing:g} rpm (K_v {response.dynamic_factor().loc[crossing]:.4f})")
        for factor in BESIDE:
            n = round(crossing * factor, 1)
            freq = harmonic_response(variant, [n], harmonics, linearization=a.linearization)
            lc = dict(input_speed_rpm=n, ramp_time_s=RAMP_S, end_time_s=END_S)
            run = dataclasses.replace(variant, gearbox=spec.with_fields("load_case", **lc))
            t0 = time.perf_counter()
            result = run_variant(run, t_end_s="settled")
            assert result.ok, result.meta.get("reason")
            sig = result.signals
            t = sig["time_s"].to_numpy()
            dt = float(t[-1] - t[-2])  # the recorded step (a run may start with shorter ones)
            f_mesh = mesh_frequency_hz(spec, n)
            k = int(round(math.floor(WINDOW_S * f_mesh) / f_mesh / dt))
            if not np.allclose(np.diff(t[-k - 1:]), dt, rtol=1e-6):
                raise RuntimeError("the analysed window is not uniformly sampled")
            print(f"  {n:g} rpm ({factor:g} x): time run {time.perf_counter() - t0:.0f} s, settled "
                  f"{result.meta.get('settled')} at {result.meta.get('settled_at_s')} s, window {k * dt:.4f} s "
                  f"ending {t[-1]:.4f} s")
            start = float(result.meta.get("settled_at_s") or t[-2 * k])
            long = int(round(math.floor((t[-1] - start) * f_mesh) / f_mesh / dt))  # the settled part, whole cycles
            f_out = abs(spec.gears.sun_teeth / spec.gears.ring_teeth * n / 60.0)  # the ring's rotation [Hz]
            bolts = spec.components_assumed.ring_bolt_count
            print(f"    settled part {long * dt:.3f} s (resolution {1.0 / (long * dt):.1f} Hz): lines at exactly "
                  f"h f_mesh, and at 2 f_mesh -/+ {bolts} f_ring (f_ring {f_out:.2f} Hz, {bolts} bolts)")
            if a.save:
                Path(a.save).mkdir(parents=True, exist_ok=True)
                sig.to_parquet(Path(a.save) / f"{variant.name}_{n:g}rpm.parquet")
            for column in COLUMNS:
                timed = harmonic_amplitudes(sig[column].to_numpy()[-k:], dt, f_mesh, (1, 2))
                before = harmonic_amplitudes(sig[column].to_numpy()[-2 * k:-k], dt, f_mesh, (1, 2))
                fd = freq.amplitudes(column).iloc[0].to_numpy()[:2]
                family = [c for c in freq.indicators if ("accel" in c) == ("accel" in column) and "max" not in c
                          and c != "dynamic_factor" and "transmission" not in c]
                scale = max(freq.amplitudes(c).iloc[0].to_numpy()[:2].max() for c in family)
                cells = []
                for h in (0, 1):
                    rel = fd[h] / timed[h] - 1.0
                    judged = fd[h] >= CANCELLED * scale
                    if judged:
                        worst = max(worst, abs(rel))
                    cells.append(f"{h + 1}x freq {fd[h]:.4g} time {timed[h]:.4g} ({100 * rel:+.1f} %"
                                 f"{'' if judged else ', cancelled: not judged'}; moved "
                                 f"{100 * (timed[h] / before[h] - 1.0):+.1f} %)")
                print(f"    {column}: " + "; ".join(cells))
                x = sig[column].to_numpy()[-long:]
                lines = [line_amplitude(x, dt, h * f_mesh) for h in (1, 2)]
                lines += [line_amplitude(x, dt, 2 * f_mesh + s * bolts * f_out) for s in (-1, 1)]
                print(f"      settled part: 1x {lines[0]:.4g}, 2x {lines[1]:.4g}; 2 f_mesh -/+ {bolts} f_ring "
                      f"{lines[2]:.4g} / {lines[3]:.4g}")
            fo = np.stack([sig[f"outer_mesh_force_{i + 1}_n"].to_numpy()[-k:] for i in range(spec.gears.planet_count)],
                          axis=1)
            fi = np.stack([sig[f"inner_mesh_force_{i + 1}_n"].to_numpy()[-k:] for i in range(spec.gears.planet_count)],
                          axis=1)
            kv_t, kv_f = _kv(fo, fi), float(freq.dynamic_factor().iloc[0])
            kv_b = _kv(*(np.stack([sig[f"{kind}_mesh_force_{i + 1}_n"].to_numpy()[-2 * k:-k]
                                   for i in range(spec.gears.planet_count)], axis=1) for kind in ("outer", "inner")))
            rel = (kv_f - 1.0) / (kv_t - 1.0) - 1.0
            worst = max(worst, abs(rel))
            print(f"    K_v - 1: freq {kv_f - 1:.4g} time {kv_t - 1:.4g} ({100 * rel:+.1f} %; moved "
                  f"{100 * ((kv_t - 1.0) / (kv_b - 1.0) - 1.0):+.1f} %)")
            kv_p = periodic_peak_factor(np.hstack([fo, fi]), dt, f_mesh, harmonics)
            print(f"      the window's mesh-periodic part (1x-{harmonics}x): K_v - 1 {kv_p - 1:.4g} "
                  f"({100 * ((kv_f - 1.0) / (kv_p - 1.0) - 1.0):+.1f} %); the rest: {kv_t - kv_p:+.4g} of the mean "
                  "force")
            if a.angles:
                _angles(variant, n, harmonics, a.angles, f_out)
    if not a.lumped_only:
        print(f"\nlargest judged difference: {100 * worst:.1f} % (goal 10 %)")
    if not a.no_lumped:
        lumped_checks(a.gearbox)
    print(load_average())


def _angles(variant, n: float, harmonics: int, count: int, f_out: float) -> None:
    """The frequency domain at ``n`` [rpm] linearised at ``count`` gear angles over one ring revolution (t* = T +
    j / (count f_ring)): K_v - 1 and the 2x bearing accelerations' complex mean and RMS over the angles (the time
    domain's line at exactly 2 f_mesh is the mean; a rotating asymmetry's sidebands carry the rest)."""
    from flexgear.modal.linear import linearize

    ramp = variant.gearbox.load_case.ramp_time_s
    kv, waves = [], {c: [] for c in COLUMNS if "accel" in c}
    for j in range(count):
        freq = harmonic_response(linearize(variant, speed_rpm=n, t_star=ramp + j / (count * f_out)), [n], harmonics)
        kv.append(float(freq.dynamic_factor().iloc[0]) - 1.0)
        for c, w in waves.items():
            w.append(complex(freq.complex(c).iloc[0][2]))
    print(f"    frequency domain at {count} gear angles over one ring revolution: K_v - 1 {min(kv):.4g} to "
          f"{max(kv):.4g}; 2x bearing accelerations, |mean| / RMS / min-max over the angles:")
    for c, w in waves.items():
        z = np.array(w)
        print(f"      {c}: {abs(z.mean()):.3g} / {np.sqrt(np.mean(np.abs(z) ** 2)):.3g} / "
              f"{np.abs(z).min():.3g}-{np.abs(z).max():.3g}")


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
                   help="the multibody models' linearisation at each check speed (flexgear.harmonic.harmonic_response; "
                        "the sweep that locates the crossing: spin)")
    c.add_argument("--angles", type=int, default=0,
                   help="also linearise at this many gear angles over one ring revolution at each check speed")
    c.add_argument("--save", default=None, help="directory: each time run's signals as <model>_<speed>rpm.parquet")
    c.add_argument("--gearbox", default=str(ROOT / "model_variants" / "gearbox.toml"),
                   help="gearbox file of the lumped model's checks")
    a = ap.parse_args()
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    {"speed": speed, "checks": checks}[a.section](a)


if __name__ == "__main__":
    main()
