"""Command line: ``flexgear run | matrix | sweep | lpm | compare | report | meshes | animate``.

Each subcommand is a thin wrapper over one library function; the heavy modules are imported
only by the subcommand that needs them.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["main"]


def _cmd_run(a: argparse.Namespace) -> int:
    from flexgear.mbs.run import run_variant
    from flexgear.results import save_result
    from flexgear.spec import load_variant

    variant = load_variant(a.variant)
    result = run_variant(variant, t_end_s=a.t_end, progress=True, record_states_every=a.states)
    out = save_result(result, Path(a.out) / variant.name)
    print(f"{variant.name}: {result.meta['status']} in {result.meta.get('wall_time_s', 0):.1f} s -> {out}")
    if not result.ok:
        print(f"reason: {result.meta.get('reason')}", file=sys.stderr)
        return 1
    return 0


def _cmd_matrix(a: argparse.Namespace) -> int:
    from flexgear.study.matrix import run_matrix

    table = run_matrix([Path(p) for p in a.variants], out_dir=Path(a.out), t_end_s=a.t_end,
                       workers=a.workers, scheduler=a.scheduler, progress=True, reference=a.reference)
    wanted = ["variant", "status", "wall_time_s", "bias_pct", "cv_pct", "distance_pct", "zone", "selected", "reason"]
    print(table[[c for c in wanted if c in table.columns]].to_string(index=False))
    return 0


def _cmd_sweep(a: argparse.Namespace) -> int:
    from flexgear.study.sweep import load_sweep, run_sweep

    plan = load_sweep(a.sweep, all_combinations=True if a.all_combinations else None)
    out = Path(a.out) if a.out else Path("results") / f"sweep_{plan.name}"
    table = run_sweep(plan, out, t_end_s=a.t_end, workers=a.workers, scheduler=a.scheduler, reference=a.reference)
    wanted = ["variant", *plan.parameters, "eps_beta", "status", "wall_time_s", "distance_pct", "zone"]
    print(table[[c for c in wanted if c in table.columns]].to_string(index=False))
    print(f"sweep table -> {out / 'sweep.csv'}; report: flexgear report {out}")
    return 0


def _cmd_lpm(a: argparse.Namespace) -> int:
    import tomllib

    from flexgear.lumped.run import run_lumped
    from flexgear.results import save_result
    from flexgear.spec import load_gearbox, load_variant

    with open(a.gearbox, "rb") as fh:  # a gearbox file, or a variant file (its gearbox with its overrides)
        is_variant = "components" in tomllib.load(fh)
    spec = load_variant(a.gearbox).gearbox if is_variant else load_gearbox(a.gearbox)
    result = run_lumped(spec, t_end_s=a.t_end, progress=True)
    out = save_result(result, Path(a.out) / "lumped")
    print(f"lumped: {result.meta['status']} in {result.meta.get('wall_time_s', 0):.2f} s -> {out}")
    return 0 if result.ok else 1


def _cmd_compare(a: argparse.Namespace) -> int:
    from flexgear.results import load_result
    from flexgear.study.compare import compare_results

    table6, table7 = compare_results(load_result(a.result_a), load_result(a.result_b))
    print(table6.to_string())
    print()
    print(table7.to_string())
    return 0


def _cmd_report(a: argparse.Namespace) -> int:
    from flexgear.report.pages import build_report

    path = build_report(Path(a.results), Path(a.output))
    print(f"report -> {path}")
    return 0


def _cmd_animate(a: argparse.Namespace) -> int:
    from flexgear.report.animate import write_animation

    path = write_animation(Path(a.run_dir), a.out, scale=a.scale)
    print(f"animation -> {path} (open in ParaView)")
    return 0


def _cmd_meshes(a: argparse.Namespace) -> int:
    from flexgear.fe.mesh import build_meshes
    from flexgear.fe.reduced import component_reduced_body
    from flexgear.spec import GEOMETRY_COMPONENTS, load_gearbox

    spec = load_gearbox(a.gearbox)
    build_meshes(spec, a.level, progress=True)
    if a.no_reduce:
        return 0
    for component in GEOMETRY_COMPONENTS:
        body = component_reduced_body(spec, component, a.level, progress=True)
        print(f"{component}: {body.n_modes} modes, first {body.frequencies_hz[0]:.0f} Hz")
    return 0


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="flexgear", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)

    r = sub.add_parser("run", help="run one variant file with the Exudyn backend")
    r.add_argument("variant")
    r.add_argument("--t-end", type=float, default=None, help="simulated time [s] (default: the load case's)")
    r.add_argument("--out", default="results", help="results folder (default: results)")
    r.add_argument("--states", type=int, default=0, metavar="N",
                   help="also record the bodies' states (frames, modal coordinates) every N steps, for "
                        "`flexgear animate` (default: 0, none)")
    r.set_defaults(func=_cmd_run)

    m = sub.add_parser("matrix", help="run a matrix of variant files and screen them")
    m.add_argument("variants", nargs="+")
    m.add_argument("--t-end", type=float, default=None)
    m.add_argument("--out", default="results")
    m.add_argument("--workers", type=int, default=2)
    m.add_argument("--scheduler", default=None, help="Dask scheduler address (default: local processes)")
    m.add_argument("--reference", default=None, metavar="NAME",
                   help="screen against this variant (dynamic indicators, Bias against its values) instead of "
                        "theory (default: [screening] reference of the gearbox file)")
    m.set_defaults(func=_cmd_matrix)

    sw = sub.add_parser("sweep", help="run a parameter sweep file (grid over gearbox fields x variants)")
    sw.add_argument("sweep", help="sweep file (TOML; see flexgear.study.sweep)")
    sw.add_argument("--out", default=None, help="results folder (default: results/sweep_<name>)")
    sw.add_argument("--t-end", type=float, default=None, help="simulated time [s] (default: the load case's)")
    sw.add_argument("--workers", type=int, default=2)
    sw.add_argument("--scheduler", default=None, help="Dask scheduler address (default: local processes)")
    sw.add_argument("--all-combinations", action="store_true",
                    help="run every base variant in all 2^5 rigid/flexible forms")
    sw.add_argument("--reference", default=None, metavar="NAME", help="screen against this variant")
    sw.set_defaults(func=_cmd_sweep)

    lp = sub.add_parser("lpm", help="run the lumped-parameter model of a gearbox (or variant) file")
    lp.add_argument("gearbox")
    lp.add_argument("--t-end", type=float, default=None)
    lp.add_argument("--out", default="results")
    lp.set_defaults(func=_cmd_lpm)

    c = sub.add_parser("compare", help="Tables 6 and 7 from two saved runs")
    c.add_argument("result_a")
    c.add_argument("result_b")
    c.set_defaults(func=_cmd_compare)

    rp = sub.add_parser("report", help="PDF screening report from saved results")
    rp.add_argument("results")
    rp.add_argument("--output", default="reports/screening_report.pdf")
    rp.set_defaults(func=_cmd_report)

    an = sub.add_parser("animate", help="VTK time series (.pvd + .vtu) of the deformed bodies of a run")
    an.add_argument("run_dir", help="a run folder whose run recorded states (flexgear run ... --states N)")
    an.add_argument("--out", default=None, help="output folder (default: RUN_DIR/animation)")
    an.add_argument("--scale", type=float, default=1.0, help="factor on the elastic deformation (default: 1)")
    an.set_defaults(func=_cmd_animate)

    me = sub.add_parser("meshes", help="build (or load from cache) the component meshes and reduced bodies")
    me.add_argument("gearbox", nargs="?", default="model_variants/gearbox.toml")
    me.add_argument("--level", default="coarse", help="mesh level of gearbox.toml [meshing_assumed] (default: coarse)")
    me.add_argument("--no-reduce", action="store_true", help="meshes only, no reduced flexible bodies")
    me.set_defaults(func=_cmd_meshes)
    return p


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, FileNotFoundError) as exc:  # SpecError is a ValueError
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
