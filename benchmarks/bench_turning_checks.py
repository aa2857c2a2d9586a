"""The planetary stage's turning carrier against time integration and against full FE: the figures behind
tests/test_modal_impulse.py's planetary case and tests/test_spur_planetary_example.py, printed in full.

- ``impulse VARIANT...``: each variant's linearised modes (flexgear.modal.linearize, at its load case's speed) and the
  poles of its impulse record (flexgear.modal.impulse, read in the carrier's axes in the planetary stage), each
  clear pole beside its nearest mode; ``--step-s`` and ``--settle-s`` as the tests (10 us, 50 ms), the ramps
  shortened to 5 ms; ``--ground-axes`` reads the record in ground axes instead (each in-plane mode then shows at
  f +- the carrier's speed).
- ``full-fe VARIANT``: the linear model at rest against the assembly with full FE bodies
  (flexgear.modal.full_fe_check); ``--seat-rbe3`` leaves the interfaces the reductions hold rigid free to deform.

Run: python benchmarks/bench_turning_checks.py impulse examples/spur_planetary/rigid.toml
     python benchmarks/bench_turning_checks.py full-fe examples/spur_planetary/flexible.toml [--seat-rbe3]
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from flexgear.modal import impulse as impulse_module  # noqa: E402
from flexgear.modal import linearize, modes  # noqa: E402
from flexgear.modal.full_fe_check import compare_full_fe  # noqa: E402
from flexgear.spec import load_variant  # noqa: E402

F_MAX_HZ = 3000.0
ORDER = 80
SAMPLE_S = 4.0e-5
WINDOW_S = 0.08
RAMP_S = 0.005
SHOWN = 0.01  # poles of at least this share of the largest amplitude are listed


def impulse(files: list[str], step_s: float, settle_s: float, ground_axes: bool) -> None:
    for file in files:
        v = load_variant(file)
        v = dataclasses.replace(v, gearbox=v.gearbox.with_fields("load_case", ramp_time_s=RAMP_S))
        lin = modes(linearize(v), F_MAX_HZ)
        response = impulse_module.impulse_response(v, window_s=WINDOW_S, step_s=step_s, settle_s=settle_s,
                                                   carrier_axes=not ground_axes)
        poles = impulse_module.damped_poles(response, ORDER, sample_s=SAMPLE_S, f_max_hz=F_MAX_HZ)
        largest = max(p.amplitude for p in poles)
        print(f"{file}: step {step_s * 1e6:g} us, settled {settle_s * 1e3:g} ms")
        print("   pole [Hz]  zeta    share |  mode [Hz]  zeta    kind        | f error %")
        for p in poles:
            if p.amplitude < SHOWN * largest:
                continue
            j = int(np.argmin(np.abs(lin.frequencies_hz - p.frequency_hz)))
            err = 100.0 * (p.frequency_hz / lin.frequencies_hz[j] - 1.0)
            print(f"  {p.frequency_hz:9.1f}  {p.damping_ratio:.4f}  {p.amplitude / largest:5.3f} | "
                  f"{lin.frequencies_hz[j]:9.1f}  {lin.damping_ratios[j]:.4f}  {lin.kinds[j]:<11} | {err:+.3f}")


def full_fe(file: str, seat_rbe3: bool) -> None:
    result = compare_full_fe(load_variant(file), hold_rigid_patches=not seat_rbe3, progress=print)
    print(result.table())
    print({k: round(v, 1) for k, v in result.seconds.items()})


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="what", required=True)
    a = sub.add_parser("impulse")
    a.add_argument("variants", nargs="+")
    a.add_argument("--step-s", type=float, default=1.0e-5)
    a.add_argument("--settle-s", type=float, default=0.05)
    a.add_argument("--ground-axes", action="store_true")
    b = sub.add_parser("full-fe")
    b.add_argument("variant")
    b.add_argument("--seat-rbe3", action="store_true")
    args = ap.parse_args(argv)
    if args.what == "impulse":
        impulse(args.variants, args.step_s, args.settle_s, args.ground_axes)
    else:
        full_fe(args.variant, args.seat_rbe3)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
