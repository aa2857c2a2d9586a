"""Command line ``flexgear modes VARIANT [--speed-rpm R] [--f-max-hz F] [--out DIR]``.

Linearises the variant at its operating point (flexgear.modal.linear), prints one line per mode (frequency, damping
ratio, kind, multiplet spread, the components holding most kinetic and strain energy) and writes
DIR/<variant>/modes.csv (flexgear.modal.modes.Modes.table: mode, frequency_hz, damping_ratio, kind, multiplicity,
spread_pct, kinetic_<component>, strain_<component>). The parser pieces follow flexgear.cli's pattern:
:data:`SUBCOMMAND` (name, help, arguments, command) or :func:`add_parsers`.
"""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["SUBCOMMAND", "add_parsers", "args_modes", "cmd_modes"]


def args_modes(p: argparse.ArgumentParser) -> None:
    """The arguments of ``flexgear modes``."""
    p.add_argument("variant", help="variant file (model_variants/model1.toml ...)")
    p.add_argument("--speed-rpm", type=float, default=None, metavar="R",
                   help="input speed in rpm (default: the load case's; 0: at rest)")
    p.add_argument("--f-max-hz", type=float, default=None, metavar="F", help="highest frequency in Hz (default: all)")
    p.add_argument("--out", default="results", metavar="DIR",
                   help="results folder; the table goes to OUT/<variant name>/modes.csv (default: %(default)s)")


def cmd_modes(a: argparse.Namespace) -> int:
    """Run ``flexgear modes``; returns the exit code."""
    from flexgear.modal import linearize, modes
    from flexgear.spec import load_variant

    variant = load_variant(a.variant)
    result = modes(linearize(variant, speed_rpm=a.speed_rpm), a.f_max_hz)
    table = result.table()
    out = Path(a.out) / variant.name
    out.mkdir(parents=True, exist_ok=True)
    table.to_csv(out / "modes.csv", index=False)
    kinetic = table.filter(regex="^kinetic_")
    strain = table.filter(regex="^strain_")
    speed = result.model.speed_rpm
    print(f"{variant.name}: {len(table)} modes at {speed:g} rpm, {result.model.n} coordinates")
    print(f"{'mode':>4} {'f [Hz]':>10} {'zeta':>7} {'kind':<16} {'n':>2} {'spread %':>9}  most kinetic / strain energy")
    for i, row in table.iterrows():
        k, s = kinetic.iloc[i], strain.iloc[i]
        print(f"{row['mode']:>4d} {row['frequency_hz']:>10.2f} {row['damping_ratio']:>7.4f} {row['kind']:<16} "
              f"{row['multiplicity']:>2d} {row['spread_pct']:>9.4f}  {k.idxmax()[8:]} {k.max():.2f} / "
              f"{s.idxmax()[7:]} {s.max():.2f}")
    print(f"-> {out / 'modes.csv'}")
    return 0


SUBCOMMAND = ("modes", "natural frequencies, damping and mode kinds of a variant at its operating point",
              args_modes, cmd_modes)


def add_parsers(subparsers) -> None:
    """Add ``modes`` to an ``argparse`` sub-parser set (``parser.add_subparsers()``)."""
    name, help_text, add_args, func = SUBCOMMAND
    sp = subparsers.add_parser(name, help=help_text, description=help_text)
    add_args(sp)
    sp.set_defaults(func=func)
