"""Which dynamic cut-off, floating-frame formulation and seat load of the dropped modes keep a flexible variant's
signals within the agreement rule (means within 0.1 %, 1x mesh amplitudes within 2 %) of the full basis, and at
what cost?

Run: nice -n 5 python benchmarks/bench_residual.py [--case model4] [--cuts 0 4 8] [--frames ffrf linear]
     [--seat-loads dynamic quasi_static] [--law impact] [--ramp 0.006] [--t-end 0.024] [--window 0.012] [--step 1e-5]

Each cut-off (gearbox.toml [reduction_assumed] dynamic_cutoff_mesh_orders; 0 = every mode of the converged
basis dynamic) with each floating frame (``floating_frame``: "ffrf" Exudyn's nonlinear terms, "linear"
flexgear.mbs.spin) and each seat load of the dropped modes (``residual_seat_loads``) runs the variant on a
shortened load case; the first case is the reference. Printed: the dynamic modes per gear, the solve's CPU time,
and against the reference the worst relative difference of the means and of the 1x mesh amplitudes of every
signal over the window (flexgear.study.agreement), with the worst signals named.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

from bench_speed import load_average

from flexgear.fe.reduced import component_reduced_body
from flexgear.mbs.run import run_variant
from flexgear.spec import load_variant
from flexgear.study.agreement import signal_agreement
from flexgear.theory import theory

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", default="model4")
    ap.add_argument("--cuts", type=float, nargs="+", default=[0.0, 4.0, 8.0])
    ap.add_argument("--frames", nargs="+", default=None, choices=["ffrf", "linear"],
                    help="floating frames to run (default: the variant's own; every mode dynamic with 'ffrf' "
                         "costs minutes: model 7 790 s CPU for 0.024 s)")
    ap.add_argument("--seat-loads", nargs="+", default=["dynamic"], choices=["dynamic", "quasi_static"])
    ap.add_argument("--law", default="impact", choices=["impact", "iso6336"])
    ap.add_argument("--ramp", type=float, default=0.006, help="ramp time [s] of the shortened load case")
    ap.add_argument("--t-end", type=float, default=0.024, help="simulated time [s]")
    ap.add_argument("--window", type=float, default=0.012, help="start [s] of the compared window")
    ap.add_argument("--step", type=float, default=None, help="time step [s] (default: Table 5's)")
    a = ap.parse_args()
    v = load_variant(ROOT / "model_variants" / f"{a.case}.toml")
    g = v.gearbox
    lc = dataclasses.replace(g.load_case, ramp_time_s=a.ramp, end_time_s=a.t_end,
                             step_size_s=a.step or g.load_case.step_size_s)
    f_mesh = theory(g).mesh_frequency
    print(f"bench_residual: {a.case}, law {a.law}, ramp {a.ramp} s, {a.t_end} s simulated, step {lc.step_size_s} s, "
          f"window from {a.window} s, mesh frequency {f_mesh:.0f} Hz; {load_average()}", flush=True)
    runs = {}
    frames = a.frames or [g.reduction_assumed.floating_frame]
    cases = [(cut, frame, seat) for cut in a.cuts for frame in frames for seat in a.seat_loads]
    for cut, frame, seat in cases:
        red = dataclasses.replace(g.reduction_assumed, dynamic_cutoff_mesh_orders=cut, floating_frame=frame,
                                  residual_seat_loads=seat)
        spec = g.with_changes(load_case=lc, reduction_assumed=red, contact=dataclasses.replace(g.contact, law=a.law))
        c0 = time.process_time()
        run = run_variant(dataclasses.replace(v, gearbox=spec))
        cpu = time.process_time() - c0
        runs[cut, frame, seat] = run
        label = "every mode" if cut == 0 else f"below {cut:g} x f_mesh = {cut * f_mesh / 1e3:.1f} kHz"
        bodies = {gear: component_reduced_body(g, gear, v.mesh_level) for gear in ("sun", "planet", "ring")}
        label += ": " + ", ".join(f"{gear} {b.modes_below(cut * f_mesh) if cut else b.n_modes}/{b.n_modes}"
                                  for gear, b in bodies.items())
        print(f"  cut-off {cut:4g}, {frame}, seat loads {seat} ({label}): "
              f"{'ok' if run.ok else 'FAILED ' + str(run.meta.get('reason'))}, "
              f"cpu {cpu:7.1f} s", flush=True)
    ref = runs[cases[0]]
    for case in cases[1:]:
        if not (ref.ok and runs[case].ok):
            continue
        cut, frame, seat = case
        agr = signal_agreement(ref, runs[case], (a.window, a.t_end), f_mesh)
        t = agr.table
        worst_amp = t["amp_diff"].abs().sort_values(ascending=False).head(3)
        worst_mean = t["mean_diff"].abs().sort_values(ascending=False).head(3)
        print(f"  cut-off {cut:g}, {frame}, {seat} vs {cases[0][0]:g}, {cases[0][1]}, {cases[0][2]}: "
              f"worst mean {agr.worst_mean:.2e} "
              f"({', '.join(f'{k} {x:.1e}' for k, x in worst_mean.items())}); worst 1x amplitude "
              f"{agr.worst_amplitude:.2e} ({', '.join(f'{k} {x:.1e}' for k, x in worst_amp.items())}); "
              f"agreement rule {'met' if agr.ok() else 'not met'}", flush=True)
        for kind in ("outer", "inner"):
            row = t.loc[f"{kind}_mesh_force_1_n"]
            print(f"    {kind} mesh force 1: mean {row.ref_mean:.2f} -> {row.new_mean:.2f} N, 1x "
                  f"{row.ref_amp_1x:.3f} -> {row.new_amp_1x:.3f} N ({100 * row.amp_diff:+.1f} %)")


if __name__ == "__main__":
    main()
