"""Command line ``flexgear sweep-speed VARIANT [--speeds-rpm 500:7000:200] [--harmonics 10] [--lumped] [--out DIR]``.

The steady harmonic response to the transmission-error excitation over a speed grid (flexgear.harmonic.response):
writes DIR/<variant>/sweep_speed/response.csv (speed_rpm, harmonic, frequency_hz, indicator, amplitude, phase)
and one PNG per indicator (amplitude over speed, a line per mesh harmonic), and prints K_v's largest value.
``--lumped``: the lumped model of the variant's gearbox instead of the multibody model. The parser pieces follow
flexgear.cli's pattern: :data:`SWEEP_SPEED` (name, help, arguments, command).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from flexgear.modal.cli import speeds_rpm

__all__ = ["SWEEP_SPEED", "args_sweep_speed", "cmd_sweep_speed"]


def args_sweep_speed(p: argparse.ArgumentParser) -> None:
    """The arguments of ``flexgear sweep-speed``."""
    p.add_argument("variant", help="variant file (model_variants/model1.toml ...)")
    p.add_argument("--speeds-rpm", type=speeds_rpm, default=speeds_rpm("500:7000:200"), metavar="A:B:S",
                   help="input speeds in rpm, START:STOP:STEP or a list a,b,c (default: 500:7000:200)")
    p.add_argument("--harmonics", type=int, default=10, metavar="H", help="mesh harmonics 1..H (default: 10)")
    p.add_argument("--lumped", action="store_true", help="the lumped model of the variant's gearbox")
    p.add_argument("--linearization", choices=("spin", "quadratic", "each"), default="spin",
                   help="multibody model: linearise at two speeds and fit the spin terms (G ~ Omega, K ~ Omega^2), "
                        "at three and interpolate, or at each speed (default: spin)")
    p.add_argument("--out", default="results", metavar="DIR",
                   help="results folder; the files go to OUT/<variant name>/sweep_speed[_lumped]/ "
                        "(default: %(default)s)")


def cmd_sweep_speed(a: argparse.Namespace) -> int:
    """Run ``flexgear sweep-speed``; returns the exit code."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from flexgear.harmonic.lumped import lumped_harmonic_response
    from flexgear.harmonic.response import harmonic_response
    from flexgear.spec import load_variant

    variant = load_variant(a.variant)
    if a.lumped:
        response = lumped_harmonic_response(variant.gearbox, a.speeds_rpm, a.harmonics)
    else:
        response = harmonic_response(variant, a.speeds_rpm, a.harmonics, linearization=a.linearization)
    out = Path(a.out) / variant.name / ("sweep_speed_lumped" if a.lumped else "sweep_speed")
    out.mkdir(parents=True, exist_ok=True)
    response.table.to_csv(out / "response.csv", index=False)
    for indicator in response.indicators:
        fig, ax = plt.subplots(figsize=(8, 4.5))
        response.plot(ax, indicator)
        fig.tight_layout()
        fig.savefig(out / f"{indicator}.png", dpi=120)
        plt.close(fig)
    kv = response.dynamic_factor()
    print(f"{response.model}: {len(kv)} speeds x {a.harmonics} harmonics in {response.wall_time_s:.1f} s; "
          f"K_v max {kv.max():.4f} at {kv.idxmax():g} rpm")
    print(f"-> {out}")
    return 0


SWEEP_SPEED = ("sweep-speed", "steady harmonic response to the transmission-error excitation over a speed range",
               args_sweep_speed, cmd_sweep_speed)
