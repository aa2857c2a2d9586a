"""Command lines ``flexgear modes``, ``flexgear campbell`` and ``flexgear modal-screening``.

``flexgear modes VARIANT [--speed-rpm R] [--f-max-hz F] [--samples J] [--out DIR]`` linearises the variant at its
operating point over one revolution of its flexible gears (flexgear.modal.period), prints one line per mode
(mean frequency, damping ratio, kind, spread over the revolution, multiplet and its split, the components holding
most kinetic and strain energy) and writes DIR/<variant>/modes.csv (flexgear.modal.eigenmodes.Modes.table: mode,
frequency_hz, damping_ratio, kind, spread_pct, multiplicity, split_pct, kinetic_<component>, strain_<component>).

``flexgear campbell VARIANT [--speeds-rpm 0:6000:500] [--f-max-hz F] [--out DIR]`` (flexgear.modal.campbell_diagram)
writes DIR/<variant>/campbell.csv (speed_rpm, mode, frequency_hz, damping_ratio, kind), crossings.csv (speed_rpm, order,
mode, kind, frequency_hz) and campbell.png.

``flexgear modal-screening VARIANT [--f-band-hz F] [--threshold S] [--out DIR]`` (flexgear.modal.screening; VARIANT
the all-flexible model 7) prints and writes DIR/<variant>/modal_screening.csv (component,
weighted_elastic_strain_share, must_be_flexible) and the recommended variant beside it.

The parser pieces follow flexgear.cli's pattern: :data:`SUBCOMMAND`, :data:`CAMPBELL`, :data:`SCREENING` (name,
help, arguments, command) or :func:`add_parsers`.
"""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["CAMPBELL", "SCREENING", "SUBCOMMAND", "add_parsers", "args_campbell", "args_modes", "args_screening",
           "cmd_campbell", "cmd_modes", "cmd_screening", "speeds_rpm"]


def args_modes(p: argparse.ArgumentParser) -> None:
    """The arguments of ``flexgear modes``."""
    p.add_argument("variant", help="variant file (model_variants/model1.toml ...)")
    p.add_argument("--speed-rpm", type=float, default=None, metavar="R",
                   help="input speed in rpm (default: the load case's; 0: at rest)")
    p.add_argument("--f-max-hz", type=float, default=None, metavar="F", help="highest frequency in Hz (default: all)")
    p.add_argument("--samples", type=int, default=None, metavar="J",
                   help="operating points over one revolution of the slowest flexible gear (default: "
                        "flexgear.modal.period.DEFAULT_SAMPLES)")
    p.add_argument("--out", default="results", metavar="DIR",
                   help="results folder; the table goes to OUT/<variant name>/modes.csv (default: %(default)s)")


def cmd_modes(a: argparse.Namespace) -> int:
    """Run ``flexgear modes``; returns the exit code."""
    from flexgear.modal.period import DEFAULT_SAMPLES, period_modes
    from flexgear.spec import load_variant

    variant = load_variant(a.variant)
    result = period_modes(variant, a.speed_rpm, a.f_max_hz,
                          samples=DEFAULT_SAMPLES if a.samples is None else a.samples)
    table = result.table()
    out = Path(a.out) / variant.name
    out.mkdir(parents=True, exist_ok=True)
    table.to_csv(out / "modes.csv", index=False)
    kinetic = table.filter(regex="^kinetic_")
    strain = table.filter(regex="^strain_")
    speed = result.model.speed_rpm
    print(f"{variant.name}: {len(table)} modes at {speed:g} rpm, {result.model.n} coordinates; spread: over one "
          "revolution of the slowest flexible gear; n, split: multiplet")
    print(f"{'mode':>4} {'f [Hz]':>10} {'zeta':>7} {'kind':<20} {'spread %':>9} {'n':>2} {'split %':>8}  "
          "most kinetic / strain energy")
    for i, row in table.iterrows():
        k, s = kinetic.iloc[i], strain.iloc[i]
        print(f"{row['mode']:>4d} {row['frequency_hz']:>10.2f} {row['damping_ratio']:>7.4f} {row['kind']:<20} "
              f"{row['spread_pct']:>9.4f} {row['multiplicity']:>2d} {row['split_pct']:>8.4f}  "
              f"{k.idxmax()[8:]} {k.max():.2f} / {s.idxmax()[7:]} {s.max():.2f}")
    print(f"-> {out / 'modes.csv'}")
    return 0


SUBCOMMAND = ("modes", "natural frequencies, damping and mode kinds of a variant at its operating point",
              args_modes, cmd_modes)


def speeds_rpm(text: str) -> list[float]:
    """``--speeds-rpm`` of every speed-grid command: ``START:STOP:STEP`` in rpm (STOP included when the steps reach
    it) or a comma-separated list."""
    try:
        if ":" in text:
            start, stop, step = (float(x) for x in text.split(":"))
            if step <= 0.0 or stop < start:
                raise ValueError
            count = int(round((stop - start) / step + 1e-9)) + 1
            speeds = [start + k * step for k in range(count)]
            return [s for s in speeds if s <= stop + 1e-9 * max(abs(stop), 1.0)]
        return [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected START:STOP:STEP or a list a,b,c in rpm, got {text!r}") from None


def args_campbell(p: argparse.ArgumentParser) -> None:
    """The arguments of ``flexgear campbell``."""
    p.add_argument("variant", help="variant file (model_variants/model1.toml ...)")
    p.add_argument("--speeds-rpm", type=speeds_rpm, default=speeds_rpm("0:6000:500"), metavar="A:B:S",
                   help="input speeds in rpm, START:STOP:STEP or a list a,b,c (default: 0:6000:500, 13 speeds)")
    p.add_argument("--f-max-hz", type=float, default=None, metavar="F",
                   help="highest frequency in Hz (default: 10x the mesh frequency at the highest speed)")
    p.add_argument("--out", default="results", metavar="DIR",
                   help="results folder; OUT/<variant name>/campbell.csv, crossings.csv, campbell.png "
                        "(default: %(default)s)")


def cmd_campbell(a: argparse.Namespace) -> int:
    """Run ``flexgear campbell``; returns the exit code."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from flexgear.modal import campbell, resonant
    from flexgear.spec import load_variant

    variant = load_variant(a.variant)

    def progress(speed: float, model, m) -> None:
        print(f"{variant.name}: {speed:8.1f} rpm, {len(resonant(m))} modes with a resonance peak "
              f"({len(m)} roots), {model.n} coordinates", flush=True)

    result = campbell(variant, a.speeds_rpm, a.f_max_hz, progress=progress)
    out = Path(a.out) / variant.name
    out.mkdir(parents=True, exist_ok=True)
    result.table.to_csv(out / "campbell.csv", index=False)
    result.crossings.to_csv(out / "crossings.csv", index=False)
    fig, ax = plt.subplots(figsize=(9, 6))
    result.plot(ax)
    fig.tight_layout()
    fig.savefig(out / "campbell.png", dpi=150)
    plt.close(fig)
    lines = result.table["mode"].nunique()
    print(f"{variant.name}: {lines} lines up to {result.f_max_hz:g} Hz, {len(result.crossings)} crossings with "
          f"orders 1x-{max(result.orders)}x (lowest MAC of a continuation {result.mac_min:.2f})")
    print(f"-> {out / 'campbell.csv'}, {out / 'crossings.csv'}, {out / 'campbell.png'}")
    return 0


def args_screening(p: argparse.ArgumentParser) -> None:
    """The arguments of ``flexgear modal-screening``."""
    from flexgear.modal.screening import THRESHOLD

    p.add_argument("variant", help="the all-flexible variant file (model_variants/model7.toml)")
    p.add_argument("--f-band-hz", type=float, default=None, metavar="F",
                   help="excitation band in Hz (default: 10x the mesh frequency at the load case's speed)")
    p.add_argument("--threshold", type=float, default=THRESHOLD, metavar="S",
                   help="weighted elastic strain share above which a component must be flexible "
                        "(default: %(default)s)")
    p.add_argument("--out", default="results", metavar="DIR",
                   help="results folder; the table goes to OUT/<variant name>/modal_screening.csv "
                        "(default: %(default)s)")


def cmd_screening(a: argparse.Namespace) -> int:
    """Run ``flexgear modal-screening``; returns the exit code."""
    from flexgear.modal import modal_screening
    from flexgear.spec import load_variant

    variant = load_variant(a.variant)
    result = modal_screening(variant, a.f_band_hz, threshold=a.threshold)
    out = Path(a.out) / variant.name
    out.mkdir(parents=True, exist_ok=True)
    result.table.to_csv(out / "modal_screening.csv", index=False)
    print(f"{variant.name}: {len(result.weights)} modes up to {result.f_band_hz:g} Hz (mesh frequency "
          f"{result.f_mesh_hz:g} Hz), threshold {result.threshold:g}")
    for _, row in result.table.iterrows():
        verdict = ("must be flexible" if row.must_be_flexible else "may be rigid" if row.judged else
                   f"not judged (rigid in {variant.name})")
        print(f"  {row.component:<13} {row.weighted_elastic_strain_share:7.4f}  {verdict}")
    print(f"recommended: {result.recommended} ({result.reason})")
    print(f"-> {out / 'modal_screening.csv'}")
    return 0


CAMPBELL = ("campbell", "Campbell diagram of a variant: natural frequencies against input speed, mesh-order "
            "crossings", args_campbell, cmd_campbell)

SCREENING = ("modal-screening", "which components must be flexible, from the all-flexible variant's modes in the "
             "excitation band", args_screening, cmd_screening)


def add_parsers(subparsers) -> None:
    """Add ``modes``, ``campbell`` and ``modal-screening`` to an ``argparse`` sub-parser set
    (``parser.add_subparsers()``)."""
    for name, help_text, add_args, func in (SUBCOMMAND, CAMPBELL, SCREENING):
        sp = subparsers.add_parser(name, help=help_text, description=help_text)
        add_args(sp)
        sp.set_defaults(func=func)
