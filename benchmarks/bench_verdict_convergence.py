"""Does the per-purpose verdict hold at a finer mesh? The quick matrix at the variants' mesh level against the same
matrix with every element size halved.

The study's variants mesh every body at ``[meshing_assumed.coarse]`` (tooth 4 mm, body 8 mm). Against half
those sizes the ring's free-free modes below 3 x the mesh frequency differ by up to 3.3 %
(benchmarks/bench_mesh_convergence.py), more than the 1 % the other bodies keep. This script writes the study's
gearbox with one more level, ``half`` (the coarse level's sizes halved, its other settings kept), and the quick
variants of ``--variants`` on it, runs that matrix against model 7 (the reference) into ``--out``, and compares
its verdict per purpose and every indicator of every variant with the same matrix at the coarse level
(``--coarse``, e.g. results/quick of ``make``): which verdict moves, and by how much each indicator does.

Run: python benchmarks/bench_verdict_convergence.py [--variants model_variants/quick] [--coarse results/quick]
                                                    [--out results/quick_half] [--workers 2]
Heavy: the half-size bodies take about 3x the coarse level's DOFs (the ring 0.69 M) and up to 8 GB each.
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from flexgear.spec import load_gearbox  # noqa: E402
from flexgear.study.matrix import run_matrix  # noqa: E402


def half_level_files(variants_dir: Path, folder: Path) -> list[Path]:
    """The study's gearbox with ``[meshing_assumed.half]`` (coarse sizes halved) and the variants of
    ``variants_dir`` on that level, written into ``folder``; returns the variant files."""
    gearbox = ROOT / "model_variants" / "gearbox.toml"
    coarse = load_gearbox(gearbox).meshing_assumed["coarse"]
    level = (f"\n[meshing_assumed.half]                # the coarse level's element sizes halved\n"
             f"tooth_size_mm = {coarse.tooth_size_mm / 2}\nbody_size_mm = {coarse.body_size_mm / 2}\n"
             f"element_order = {coarse.element_order}\n"
             f"elements_per_curvature_radius = {coarse.elements_per_curvature_radius}\n"
             f"optimisation_steps = {coarse.optimisation_steps}\n")
    text = gearbox.read_text()
    at = text.index("[meshing_assumed.default]")
    (folder / "gearbox.toml").write_text(text[:at] + level.lstrip("\n") + "\n" + text[at:])
    out = []
    for path in sorted(variants_dir.glob("model*.toml")):
        body = re.sub(r'^gearbox = ".*"$', 'gearbox = "gearbox.toml"', path.read_text(), flags=re.M)
        body = re.sub(r'^mesh_level = ".*"$', 'mesh_level = "half"', body, flags=re.M)
        (folder / path.name).write_text(body)
        out.append(folder / path.name)
    return out


def compare(coarse: Path, half: Path) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(verdict per purpose at both levels, every indicator's value at both levels and its change in the
    indicator's own unit)."""
    cols = ["purpose", "selected", "deciding_indicator", "resolved"]
    verdict = pd.read_csv(coarse / "verdict.csv")[cols].merge(
        pd.read_csv(half / "verdict.csv")[cols], on="purpose", suffixes=("_coarse", "_half"))
    verdict["moved"] = verdict["selected_coarse"].fillna("") != verdict["selected_half"].fillna("")
    keys = ["variant", "indicator"]
    a, b = pd.read_csv(coarse / "screening_indicators.csv"), pd.read_csv(half / "screening_indicators.csv")
    value = [c for c in ("bias", "value", "bias_pct") if c in a.columns][0]
    ind = a[keys + [value]].merge(b[keys + [value]], on=keys, suffixes=("_coarse", "_half"))
    ind["change"] = ind[f"{value}_half"] - ind[f"{value}_coarse"]
    return verdict, ind


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--variants", type=Path, default=ROOT / "model_variants" / "quick")
    p.add_argument("--coarse", type=Path, default=ROOT / "results" / "quick")
    p.add_argument("--out", type=Path, default=ROOT / "results" / "quick_half")
    p.add_argument("--workers", type=int, default=2)
    a = p.parse_args(argv)
    folder = Path(tempfile.mkdtemp(prefix="half_level_"))
    paths = half_level_files(a.variants, folder)
    run_matrix(paths, a.out, workers=a.workers, reference="model7", progress=True)
    if not (a.coarse / "verdict.csv").is_file():
        print(f"no verdict at the coarse level in {a.coarse}: run make first")
        return 1
    verdict, ind = compare(a.coarse, a.out)
    print(verdict.to_string(index=False))
    worst = ind.reindex(ind["change"].abs().sort_values(ascending=False).index).head(15)
    print(worst.to_string(index=False))
    ind.to_csv(a.out / "indicator_change_vs_coarse.csv", index=False)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
