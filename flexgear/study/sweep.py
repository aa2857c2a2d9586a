"""Parameter sweeps: a grid over gearbox fields times variants, run by the matrix runner.

A sweep file (TOML) names base variant files and the values of each swept field::

    variants = ["../model_variants/quick/model1.toml", "../model_variants/quick/model4.toml"]
    grid = "product"                       # or "zip" (the i-th value of every field together)
    all_combinations = false               # true: every base variant in all 2^5 rigid/flexible forms
    [parameters]
    "gears_assumed.face_width_mm" = [20.0, 40.0]
    "contact.stiffness" = [5.0e7, 1.0e8]
    mesh_level = ["coarse"]                # a variant field instead of a gearbox field

A gearbox field is ``table.field`` of gearbox.toml (a variant's ``[overrides.table]``); paths are
relative to the sweep file. Every point of the grid and every variant becomes a generated variant
file ``OUT/variants/<base>__<point>.toml`` (the base file with the point's overrides and an
absolute gearbox path), and :func:`flexgear.study.matrix.run_matrix` runs them all: finished
runs are kept (resume), failures are recorded. ``OUT/sweep.json`` describes the grid and
``OUT/sweep.csv`` / ``.parquet`` holds one row per run: the swept values, the overlap ratio
eps_beta of one helix half, status, wall time, the screening point and every indicator's mean.
"""

from __future__ import annotations

import itertools
import json
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from flexgear.cache import atomic_write_bytes
from flexgear.spec import COMPONENTS, SpecError, load_variant
from flexgear.study.matrix import run_matrix, write_table

__all__ = ["SweepPlan", "SweepResult", "load_sweep", "sweep_points", "write_variants", "run_sweep", "toml_text",
           "indicator_means"]

_VARIANT_FIELDS = ("mesh_level", "rigid_mass_properties")


@dataclass(frozen=True)
class SweepPlan:
    """A sweep file: base variants, the swept fields and their values, the grid type."""

    source: Path
    name: str
    variants: tuple[Path, ...]
    parameters: dict[str, tuple[Any, ...]]
    grid: str = "product"
    all_combinations: bool = False


def load_sweep(path: str | Path, all_combinations: bool | None = None) -> SweepPlan:
    """Read and check a sweep file (one-line SpecError naming the field otherwise)."""
    path = Path(path)
    try:
        raw = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise SpecError(path, "<file>", "file does not exist") from None
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(path, "<file>", f"is not valid TOML ({exc})") from None
    allowed = {"name", "variants", "grid", "all_combinations", "parameters"}
    unknown = sorted(set(raw) - allowed)
    if unknown:
        raise SpecError(path, unknown[0], f"unknown field; allowed: {', '.join(sorted(allowed))}")
    variants = raw.get("variants")
    if not isinstance(variants, list) or not variants or not all(isinstance(v, str) for v in variants):
        raise SpecError(path, "variants", "expected a non-empty list of variant file paths")
    grid = raw.get("grid", "product")
    if grid not in ("product", "zip"):
        raise SpecError(path, "grid", "expected 'product' or 'zip'", grid)
    params = raw.get("parameters", {})
    if not isinstance(params, dict):
        raise SpecError(path, "parameters", "expected a table of field = [values]")
    for key, values in params.items():
        if not isinstance(values, list) or not values:
            raise SpecError(path, f"parameters.{key}", "expected a non-empty list of values", values)
        if key not in _VARIANT_FIELDS and key.count(".") != 1:
            raise SpecError(path, f"parameters.{key}", "expected 'table.field' of the gearbox file or one of "
                            + ", ".join(_VARIANT_FIELDS))
    if grid == "zip" and len({len(v) for v in params.values()}) > 1:
        raise SpecError(path, "parameters", "grid 'zip' needs lists of equal length")
    combos = raw.get("all_combinations", False) if all_combinations is None else all_combinations
    return SweepPlan(path, str(raw.get("name", path.stem)), tuple((path.parent / v).resolve() for v in variants),
                     {k: tuple(v) for k, v in params.items()}, grid, bool(combos))


def sweep_points(plan: SweepPlan) -> list[dict[str, Any]]:
    """The grid: one {field: value} per point (product or zip); one empty point without parameters."""
    keys = list(plan.parameters)
    if not keys:
        return [{}]
    rows = (zip(*plan.parameters.values(), strict=True) if plan.grid == "zip"
            else itertools.product(*plan.parameters.values()))
    return [dict(zip(keys, r, strict=True)) for r in rows]


def _label(point: dict[str, Any]) -> str:
    parts = []
    for key, value in point.items():
        short = key.split(".")[-1]
        text = f"{value:g}" if isinstance(value, float) else str(value)
        parts.append(f"{short}_{text}")
    return "__".join(parts)


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def toml_text(data: dict[str, Any]) -> str:
    """TOML of a variant: top-level values, then tables (one level of sub-tables, e.g. overrides)."""
    lines = [f"{k} = {_value(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for table, body in data.items():
        if not isinstance(body, dict):
            continue
        scalars = {k: v for k, v in body.items() if not isinstance(v, dict)}
        if scalars or not body:
            lines += ["", f"[{table}]"] + [f"{k} = {_value(v)}" for k, v in scalars.items()]
        for sub, values in body.items():
            if isinstance(values, dict):
                lines += ["", f"[{table}.{sub}]"] + [f"{k} = {_value(v)}" for k, v in values.items()]
    return "\n".join(lines) + "\n"


def _forms(base: dict[str, Any], all_combinations: bool) -> list[tuple[str, dict[str, str]]]:
    """(suffix, components) of a base variant: itself, or all 2^n rigid/flexible forms of its n components
    ("rrfrf")."""
    if not all_combinations:
        return [("", dict(base["components"]))]
    names = [c for c in COMPONENTS if c in base["components"]]  # the arrangement's (no ring in a parallel pair)
    out = []
    for bits in itertools.product("rf", repeat=len(names)):
        comps = {c: ("flexible" if b == "f" else "rigid") for c, b in zip(names, bits, strict=True)}
        out.append(("_" + "".join(bits), comps))
    return out


def write_variants(plan: SweepPlan, out_dir: Path) -> tuple[list[Path], list[dict[str, Any]]]:
    """Generate the variant files of the sweep; return their paths and one description per file."""
    folder = out_dir / "variants"
    folder.mkdir(parents=True, exist_ok=True)
    paths, rows = [], []
    for base_path in plan.variants:
        base = tomllib.loads(base_path.read_text())
        base["gearbox"] = str((base_path.parent / base["gearbox"]).resolve())
        for suffix, comps in _forms(base, plan.all_combinations):
            for point in sweep_points(plan):
                data = {k: v for k, v in base.items() if k not in ("overrides", "components")}
                overrides = {t: dict(v) for t, v in base.get("overrides", {}).items()}
                for key, value in point.items():
                    if key in _VARIANT_FIELDS:
                        data[key] = value
                    else:
                        table, fieldname = key.split(".")
                        overrides.setdefault(table, {})[fieldname] = value
                varying = {k: v for k, v in point.items() if len(plan.parameters[k]) > 1}
                name = base["name"] + suffix + (f"__{_label(varying)}" if varying else "")
                data["name"] = name
                data["components"] = comps
                if overrides:
                    data["overrides"] = overrides
                path = folder / f"{name}.toml"
                text = ("# generated by flexgear sweep from " + base_path.name + "\n" + toml_text(data)).encode()
                if not path.exists() or path.read_bytes() != text:
                    atomic_write_bytes(path, text)
                load_variant(path)                    # bad swept values fail here, before any run
                rows.append({"variant": name, "base": base["name"] + suffix, **point})
                paths.append(path)
    return paths, rows


def _eps_beta(path: Path) -> float:
    """Overlap ratio of one helix half of the sun-planet mesh, b_half sin(beta) / (pi m_n)."""
    from flexgear.geometry.involute import gear_set_geometry

    geo = gear_set_geometry(load_variant(path).gearbox)
    return float(geo.sun_planet.overlap_ratio(geo.helix_face_width))


def indicator_means(run_dir: Path, settings) -> dict[str, float]:
    """Every indicator's mean over the run's settled window (flexgear.study.indicators); {} if it failed."""
    from flexgear.results import load_result
    from flexgear.study.screening import indicator_samples

    if not (run_dir / "run.json").exists():
        return {}
    result = load_result(run_dir)
    if not result.ok:
        return {}
    window, samples = indicator_samples(result, settings)
    return {"window_start_s": window.start_s, **{k: float(v.mean()) for k, v in samples.items()}}


def run_sweep(plan: SweepPlan, out_dir: str | Path, t_end_s: float | None = None, workers: int = 2,
              scheduler: str | None = None, progress: bool = True, runner=None,
              reference: str | None = None) -> pd.DataFrame:
    """Generate, run (matrix runner: resume, failures recorded) and tabulate a sweep; see the module docstring."""
    out_dir = Path(out_dir)
    paths, rows = write_variants(plan, out_dir)
    for row, path in zip(rows, paths, strict=True):
        row["eps_beta"] = _eps_beta(path)
    matrix = run_matrix(paths, out_dir, t_end_s=t_end_s, workers=workers, scheduler=scheduler, progress=progress,
                        runner=runner, reference=reference)
    settings = load_variant(paths[0]).gearbox.screening
    means = pd.DataFrame([indicator_means(out_dir / row["variant"], settings) for row in rows],
                         index=[row["variant"] for row in rows])
    table = (pd.DataFrame(rows)
             .merge(matrix[["variant", "status", "reason", "wall_time_s", "t_end_s", "bias_pct", "cv_pct",
                            "distance_pct", "zone"]], on="variant", how="left")
             .merge(means, left_on="variant", right_index=True, how="left"))
    write_table(table, out_dir / "sweep")
    meta = {"name": plan.name, "source": str(plan.source), "grid": plan.grid,
            "all_combinations": plan.all_combinations, "parameters": {k: list(v) for k, v in plan.parameters.items()},
            "variants": [str(p) for p in plan.variants]}
    atomic_write_bytes(out_dir / "sweep.json", json.dumps(meta, indent=2).encode())
    return table


@dataclass(frozen=True)
class SweepResult:
    """A finished sweep read back from its folder: ``sweep.json`` (``meta``) and ``sweep.parquet``."""

    meta: dict[str, Any]
    table: pd.DataFrame
    folder: Path | None = None

    @classmethod
    def load(cls, out_dir: str | Path) -> SweepResult:
        out_dir = Path(out_dir)
        return cls(json.loads((out_dir / "sweep.json").read_text()), pd.read_parquet(out_dir / "sweep.parquet"),
                   out_dir)

    @property
    def parameters(self) -> list[str]:
        return list(self.meta["parameters"])

    def plot(self, ax, y: str, x: str | None = None, label: str = "", **style) -> None:
        """Indicator mean ``y`` (a screening indicator key) against ``x`` (default: the first swept
        field), one line per base variant and value of the other swept fields; failed runs left out."""
        x = x or (self.parameters[0] if self.parameters else "eps_beta")
        ok = self.table[self.table["status"] == "ok"]
        varying = [p for p in self.parameters if len(self.meta["parameters"][p]) > 1]
        # eps_beta follows from the face width: a face-width sweep plotted over eps_beta is one line
        others = [p for p in varying if p != x and not (x == "eps_beta" and p.endswith("face_width_mm"))]
        for keys, part in ok.groupby(["base", *others], sort=True):
            keys = keys if isinstance(keys, tuple) else (keys,)
            text = ", ".join([str(keys[0])] + [f"{o.split('.')[-1]} {v:g}" if isinstance(v, float) else str(v)
                                               for o, v in zip(others, keys[1:], strict=True)])
            part = part.sort_values(x)
            ax.plot(part[x], part[y], "o-", label=(label + " " + text).strip(), **{"lw": 1.0, "ms": 4, **style})
