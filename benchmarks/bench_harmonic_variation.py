"""How far is the first-order harmonic response from time integration, as the mesh-stiffness variation grows?

The lumped model of a variant's gearbox (no tooth friction) at each speed: the 1x, 2x and 3x mesh-force amplitudes
of the sun-planet mesh of planet 1 from its harmonic response (flexgear.harmonic.lumped_harmonic_response: first
order in the stiffness variation) against its own settled time run (flexgear.lumped.run.run_lumped, the last
``--window`` seconds, whole mesh cycles), with the stiffness harmonics of every mesh scaled by each ``--scales``
factor in both models alike. The ratio frequency domain / time tends to 1 as the variation shrinks where the
first-order truncation is what separates them.

Run: .venv/bin/python benchmarks/bench_harmonic_variation.py examples/spur_star/rigid.toml
         [--speeds-rpm 300 2000] [--scales 1 0.3 0.1] [--ramp 0.05] [--end 0.4] [--window 0.1]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import flexgear.lumped.run as lumped_run  # noqa: E402
from flexgear.harmonic import lumped_harmonic_response, mesh_frequency_hz  # noqa: E402
from flexgear.spec import load_variant  # noqa: E402
from flexgear.study.compare import harmonic_amplitudes  # noqa: E402

COLUMN = "outer_mesh_force_1_n"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("variant", type=Path)
    p.add_argument("--speeds-rpm", type=float, nargs="+", default=[300.0, 2000.0])
    p.add_argument("--scales", type=float, nargs="+", default=[1.0, 0.3, 0.1])
    p.add_argument("--ramp", type=float, default=0.05, help="ramp time [s]")
    p.add_argument("--end", type=float, default=0.4, help="end time [s]")
    p.add_argument("--window", type=float, default=0.1, help="analysis window at the end [s]")
    a = p.parse_args(argv)
    build = lumped_run.build_lumped_model
    variant = load_variant(a.variant)
    print(f"{'rpm':>7} {'scale':>6}  {'time 1x/2x/3x [N]':>26}  {'frequency domain':>26}  ratio")
    for rpm in a.speeds_rpm:
        spec = variant.gearbox.with_fields("load_case", input_speed_rpm=rpm, ramp_time_s=a.ramp, end_time_s=a.end)
        spec = spec.with_fields("contact", friction_coefficient=0.0)
        for scale in a.scales:
            def scaled(s, scale=scale):
                model = build(s)
                return dataclasses.replace(model, harmonics=model.harmonics * scale)

            lumped_run.build_lumped_model = scaled  # both models build the lumped model through this name
            try:
                freq = lumped_harmonic_response(spec, [rpm], harmonics=spec.contact_assumed.stiffness_harmonics)
                run = lumped_run.run_lumped(spec)
            finally:
                lumped_run.build_lumped_model = build
            t = run.signals["time_s"].to_numpy()
            dt, f_mesh = float(t[-1] - t[-2]), mesh_frequency_hz(spec, rpm)
            n = int(math.floor(a.window * f_mesh) / f_mesh / dt)
            timed = harmonic_amplitudes(run.signals[COLUMN].to_numpy()[-n:], dt, f_mesh, (1, 2, 3))
            fr = freq.amplitudes(COLUMN).iloc[0].to_numpy()[:3]
            print(f"{rpm:7.0f} {scale:6.2f}  {np.array2string(timed, precision=3):>26}  "
                  f"{np.array2string(fr, precision=3):>26}  {np.array2string(fr / timed, precision=3)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
