"""The whole grid of gear sets as a benchmark: every set written as a minimal gearbox file, loaded, and each of its
gears built as an OCC solid and a coarse mesh, checked as tests/test_gear_sets.py checks its four sets.

Run: FLEXGEAR_CACHE_DIR=/tmp/grid_cache .venv/bin/python benchmarks/bench_gear_set_grid.py [--count 300]
         [--seed 2026] [--no-corners] [--mesh | --no-mesh] [--timeout 900] [--first I] [--limit N]
         [--time-limit S] [--out grid.csv] [--files DIR] [--keep-cache]

The grid (deterministic for a count and a seed):

- corners: three tooth sets (12/12/36, 12/68/150 and 126/12/150, three planets) x normal module 1 and 20 mm x normal
  pressure angle 14.5 and 25 deg x planet shift -0.5 and 0.8 x spur, single and double helix (30 deg): 72 sets;
- a Latin-hypercube sample of ``--count`` sets over the kind (spur, single or double helix, helix 8-35 deg), the
  planet's teeth (12-68), the sun's (12 up to a ring of at most 150 teeth), the normal module (1-20 mm,
  log-uniform), the normal pressure angle (14.5-25 deg) and the planet shift (-0.5...0.8). The ring has
  z_s + 2 z_p + k teeth: k a small odd or even offset (-2...2) for most sets, a large one (3-24 either way: a mean
  centre distance that profile shifts cannot reach, or too few ring teeth) for about one in seven. The planet
  count is one of 3-6 whose planets fit beside each other (reference centre distance and tip circle) for most sets,
  any of 3-6 for about one in seven; for four in five of the small offsets, the offset is one that meets the
  equal-spacing assembly condition ((z_s + z_r) divisible by the planet count), so the condition holds and fails.
  Invalid sets come with it: undercut small pinions (12 teeth, 14.5 deg, negative shift), pointed teeth (large
  shifts on few teeth), planets that overlap (large planets, 5 or 6 of them), unreachable centre distances.

Each set is a gearbox file of ``[gears]``, ``[bearings]`` and ``[load_case]`` (star arrangement, the bearings and
load of examples/spur_star) and, where the set is not the default, the two grid fields of ``[gears_assumed]``
that no other table can give: ``helix_layout = "double"`` and ``planet_shift_coefficient``. Every size follows
the gear set (flexgear.sizing). Then:

- (a) ``flexgear.load_gearbox``. A refused set raises ``SpecError`` with a one-line message that names the file
  and a field (counted per field); a refusal without a field or on more than one line, and any other exception,
  is an INTERNAL ERROR (the traceback's last line is recorded). Three conditions are also predicted here, from
  the teeth alone (the equal-spacing condition, z_r > z_p + z_s / 2, a reachable mean centre distance): a set
  accepted against the prediction is an internal error too.
- (b) each accepted set, for sun, planet and ring: its OCC solid (``flexgear.fe.mesh.component_brep``) is one solid
  whose mass, diagonal inertia and centre of mass match ``flexgear.geometry.layout.exact_mass_properties`` within
  0.1 % (the centre within 1e-3 m_n); with ``--mesh`` (the default) its second-order coarse mesh
  (``component_mesh(spec, comp, "coarse", order=2)``): every flank node within 1 um of the involute helicoid
  (``flexgear.geometry.check.flank_deviation``) and flank nodes in all 2 z half pitches (both flanks of every
  tooth), the checks of tests/test_gear_sets.py re-expressed.

Verdicts per set: ``refused`` (the field), ``ok``, ``failed`` (the checks that failed), ``build_error`` (an
exception while building an accepted set: its last line), ``internal_error``, ``timeout`` (``--timeout`` seconds
for one set) or ``crashed`` (the worker died: its signal). The sets run one after another in one worker process
(one core; Netgen and BLAS single-threaded), restarted after a timeout or a crash; each set's cache entries go to
a subfolder of ``$FLEXGEAR_CACHE_DIR`` removed after the set unless ``--keep-cache``. A CSV row per set (the
parameters, the rack undercut flags of sun and planet, the verdict, the worst errors per gear, the node counts,
the wall times of loading, solids and meshes) is written as the set finishes, and a summary at the end.
"""

from __future__ import annotations

import argparse
import csv
import math
import multiprocessing
import os
import re
import shutil
import sys
import tempfile
import time
import traceback
from collections import Counter
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
GEARS = ("sun", "planet", "ring")
KINDS = ("spur", "single", "double")
MASS_TOL = 1e-3
"""Relative tolerance of the solid's mass and diagonal inertia against the exact section integrals (0.1 %)."""
COM_TOL = 1e-3
"""Tolerance of the solid's centre of mass, in normal modules."""
FLANK_TOL = 1e-6
"""Largest distance [m] of a flank node of the coarse mesh from the involute helicoid."""

BEARINGS = {
    "input_shaft": {"radial_stiffness_n_per_m": 2.0e8, "axial_stiffness_n_per_m": 2.0e7,
                    "tilt_stiffness_nm_per_rad": 1.0e5},
    "output_shaft": {"radial_stiffness_n_per_m": 5.0e8, "axial_stiffness_n_per_m": 5.0e7,
                     "tilt_stiffness_nm_per_rad": 5.0e5},
    "planet": {"radial_stiffness_n_per_m": 5.0e8, "axial_stiffness_n_per_m": 5.0e7,
               "tilt_stiffness_nm_per_rad": 1.0e5},
}
LOAD_CASE = {"input_speed_rpm": 3000.0, "load_torque_nm": 600.0, "ramp_time_s": 0.02, "end_time_s": 0.08}

PARAMS = ("set", "source", "kind", "z_sun", "z_planet", "z_ring", "ring_offset", "planets", "module_mm",
          "helix_deg", "pressure_deg", "planet_shift")
COLUMNS = (*PARAMS, "predicted", "undercut", "verdict", "field", "detail", "load_s", "solid_s", "mesh_s", "wall_s",
           *(f"{g}_{k}" for g in GEARS for k in ("mass_err", "inertia_err", "com_err_mn", "flank_um",
                                                 "half_pitches", "nodes")),
           "peak_rss_mb")


# --------------------------------------------------------------------------- the grid
def _gear_set(source: str, kind: str, teeth: tuple[int, int, int], offset: int, planets: int, module: float,
              helix: float, pressure: float, shift: float) -> dict:
    zs, zp, zr = teeth
    return {"source": source, "kind": kind, "z_sun": zs, "z_planet": zp, "z_ring": zr, "ring_offset": offset,
            "planets": planets, "module_mm": module, "helix_deg": helix if kind != "spur" else 0.0,
            "pressure_deg": pressure, "planet_shift": shift}


def corners() -> list[dict]:
    """The 72 corner sets (module docstring)."""
    out = []
    for zs, zp, k in ((12, 12, 0), (12, 68, 2), (126, 12, 0)):
        for module in (1.0, 20.0):
            for pressure in (14.5, 25.0):
                for shift in (-0.5, 0.8):
                    for kind in KINDS:
                        out.append(_gear_set("corner", kind, (zs, zp, zs + 2 * zp + k), k, 3, module, 30.0,
                                             pressure, shift))
    return out


def sample(count: int, seed: int) -> list[dict]:
    """``count`` sets of a Latin hypercube over the continuous parameters (module docstring), the ring offset and
    planet count drawn from the same seeded generator."""
    rng = np.random.default_rng(seed)
    dims = 7
    u = (np.stack([rng.permutation(count) for _ in range(dims)], axis=1) + rng.random((count, dims))) / max(count, 1)
    out = []
    for row in u:
        kind = KINDS[min(int(row[0] * 3), 2)]
        zp = int(round(12 + row[1] * (68 - 12)))
        zs = int(round(12 + row[2] * (148 - 2 * zp - 12)))
        module = round(math.exp(row[3] * math.log(20.0)), 3)
        pressure = round(14.5 + row[4] * 10.5, 2)
        shift = round(-0.5 + row[5] * 1.3, 3)
        helix = round(8.0 + row[6] * 27.0, 2)
        # planet counts whose tip circles do not overlap at the reference centre distance, for most sets
        mt = module / math.cos(math.radians(helix if kind != "spur" else 0.0))
        tip = mt * zp + 2 * module * (1 + shift)
        fit = [n for n in range(3, 7) if mt * (zs + zp) * math.sin(math.pi / n) > tip]
        planets = int(rng.choice(fit) if fit and rng.random() < 0.85 else rng.integers(3, 7))
        if rng.random() < 1 / 7:  # far from z_s + 2 z_p: unreachable centre distance or too few ring teeth
            offset = int(rng.choice((-1, 1)) * rng.integers(3, 25))
        elif rng.random() < 0.8:  # a small offset that meets the assembly condition for the planet count
            fits = [k for k in range(-2, 3) if (2 * zs + 2 * zp + k) % planets == 0]
            offset = int(rng.choice(fits)) if fits else int(rng.integers(-2, 3))
        else:  # any small offset: the condition holds or fails
            offset = int(rng.integers(-2, 3))
        zr = max(3, zs + 2 * zp + offset)
        out.append(_gear_set("sample", kind, (zs, zp, zr), offset, planets, module, helix, pressure, shift))
    return out


def grid(count: int, seed: int, with_corners: bool = True) -> list[dict]:
    sets = (corners() if with_corners else []) + sample(count, seed)
    for i, s in enumerate(sets):
        s["set"] = i
    return sets


def predicted_refusals(s: dict) -> list[str]:
    """Refusals that follow from the teeth alone (independent of the package's checks): the field each names."""
    out = []
    zs, zp, zr, n = s["z_sun"], s["z_planet"], s["z_ring"], s["planets"]
    if zr <= zp + zs // 2:
        out.append("gears.ring_teeth")
    if (zs + zr) % n:
        out.append("gears.planet_count")
    beta, alpha_n = math.radians(s["helix_deg"]), math.radians(s["pressure_deg"])
    alpha_t = math.atan(math.tan(alpha_n) / math.cos(beta))
    mt = s["module_mm"] / math.cos(beta)
    mean = mt * (zs + zr) / 4
    lower = max(abs(mt * (zp + z) / 2) * math.cos(alpha_t) for z in (zs, -zr))
    if mean <= lower:
        out.append("gears_assumed.operating_centre_distance_mm")
    return out


def gearbox_text(s: dict) -> str:
    """The minimal gearbox file of set ``s`` (module docstring)."""
    lines = [f'title = "gear-set grid, set {s["set"]}"', "", "[gears]",
             f"sun_teeth = {s['z_sun']}", f"planet_teeth = {s['z_planet']}", f"ring_teeth = {s['z_ring']}",
             f"planet_count = {s['planets']}", f"normal_module_mm = {float(s['module_mm'])!r}",
             f"helix_angle_deg = {float(s['helix_deg'])!r}",
             f"normal_pressure_angle_deg = {float(s['pressure_deg'])!r}", 'arrangement = "star"']
    assumed = []
    if s["kind"] == "double":
        assumed.append('helix_layout = "double"')
    if s["planet_shift"] != 0.0:
        assumed.append(f"planet_shift_coefficient = {float(s['planet_shift'])!r}")
    if assumed:
        lines += ["", "[gears_assumed]", *assumed]
    for name, values in BEARINGS.items():
        lines += ["", f"[bearings.{name}]", *(f"{k} = {v!r}" for k, v in values.items())]
    lines += ["", "[load_case]", *(f"{k} = {v!r}" for k, v in LOAD_CASE.items())]
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- the checks (one set, in the worker)
def _last_line(exc: BaseException) -> str:
    lines = [x for x in "".join(traceback.format_exception_only(type(exc), exc)).strip().splitlines() if x.strip()]
    return (lines[-1] if lines else type(exc).__name__)[:400]


def _undercut(spec) -> str:
    """Sun and planet undercut by the rack criterion (h_a - x) m_n > r sin^2(alpha_t) (informative: the package
    builds an involute to the base circle, then a radial flank and a fillet; it does not refuse undercut)."""
    from flexgear.geometry.involute import gear_set_geometry

    gs = gear_set_geometry(spec)
    out = []
    for name in ("sun", "planet"):
        g = getattr(gs, name)
        if (g.addendum_coefficient - g.shift) * g.normal_module > g.reference_radius * math.sin(
                g.transverse_pressure_angle) ** 2:
            out.append(name)
    return "+".join(out)


def _check_solid(spec, comp: str, row: dict) -> list[str]:
    from netgen.occ import OCCGeometry

    from flexgear.fe.mesh import component_brep
    from flexgear.geometry.layout import exact_mass_properties
    from flexgear.geometry.solids import occ_mass_properties

    exact = exact_mass_properties(spec, comp)
    shape = OCCGeometry(str(component_brep(spec, comp))).shape
    mass, com, inertia = occ_mass_properties(shape, spec.material_assumed.density_kg_m3)
    mass_err = abs(mass / exact.mass - 1)
    inertia_err = float(np.max(np.abs(np.diag(inertia) / np.diag(exact.inertia) - 1)))
    com_err = float(np.linalg.norm(com - exact.com)) / spec.gears.normal_module_m
    row.update({f"{comp}_mass_err": f"{mass_err:.3e}", f"{comp}_inertia_err": f"{inertia_err:.3e}",
                f"{comp}_com_err_mn": f"{com_err:.3e}"})
    failed = []
    if len(shape.solids) != 1:
        failed.append(f"{comp}.solids={len(shape.solids)}")
    if not mass_err <= MASS_TOL:
        failed.append(f"{comp}.mass")
    if not inertia_err <= MASS_TOL:
        failed.append(f"{comp}.inertia")
    if not com_err <= COM_TOL:
        failed.append(f"{comp}.com")
    return failed


def _check_mesh(spec, comp: str, row: dict) -> list[str]:
    from flexgear.fe.mesh import component_mesh
    from flexgear.geometry.check import flank_deviation
    from flexgear.geometry.layout import component_layout

    layout = component_layout(spec, comp)
    mesh = component_mesh(spec, comp, "coarse", order=2)
    points = mesh.nodes[mesh.regions["flanks"]]
    row[f"{comp}_nodes"] = len(mesh.nodes)
    if len(points) == 0:
        row[f"{comp}_half_pitches"] = 0
        return [f"{comp}.no_flank_nodes"]
    dist, _, _ = flank_deviation(layout, points)
    worst = float(np.abs(dist).max())
    twist = np.array([next(q.twist for q in layout.prisms if q.section.gear and q.z0 - 1e-9 <= z <= q.z1 + 1e-9)
                      for z in points[:, 2]])
    phase = np.arctan2(points[:, 1], points[:, 0]) - twist * points[:, 2]
    teeth = layout.gear.teeth
    covered = len(np.unique(np.floor(phase / (math.pi / teeth)) % (2 * teeth)))
    row.update({f"{comp}_flank_um": f"{worst * 1e6:.3e}", f"{comp}_half_pitches": f"{covered}/{2 * teeth}"})
    failed = []
    if not worst < FLANK_TOL:
        failed.append(f"{comp}.flank")
    if covered != 2 * teeth:
        failed.append(f"{comp}.half_pitches")
    return failed


def run_set(s: dict, folder: Path, mesh: bool) -> dict:
    """Load and check one set (module docstring): its CSV row."""
    import flexgear
    from flexgear.spec import SpecError

    row = {k: s[k] for k in PARAMS}
    row["predicted"] = "+".join(predicted_refusals(s))
    path = folder / f"set{s['set']:05d}.toml"
    path.write_text(gearbox_text(s))
    t0 = time.perf_counter()
    try:
        spec = flexgear.load_gearbox(path)
    except SpecError as err:
        row["load_s"] = f"{time.perf_counter() - t0:.3f}"
        text = str(err)
        row["field"], row["detail"] = err.field, text.split(": ", 1)[-1][:300].replace("\n", " | ")
        named = bool(err.field) and err.field != "<file>" and f"field '{err.field}'" in text and str(path) in text
        row["verdict"] = "refused" if named and "\n" not in text else "internal_error"
        if row["verdict"] == "internal_error":
            row["detail"] = "refusal not on one line naming a field: " + row["detail"]
        return row
    except Exception as exc:  # noqa: BLE001  (every other exception is the finding)
        row.update(load_s=f"{time.perf_counter() - t0:.3f}", verdict="internal_error", field="",
                   detail=f"load_gearbox: {_last_line(exc)}")
        return row
    row["load_s"] = f"{time.perf_counter() - t0:.3f}"
    if row["predicted"]:
        row.update(verdict="internal_error", field="",
                   detail=f"accepted although {row['predicted']} must refuse it")
        return row
    row["undercut"] = _undercut(spec)
    failed: list[str] = []
    stage = "solid"
    try:
        t1 = time.perf_counter()
        for comp in GEARS:
            stage = f"{comp} solid"
            failed += _check_solid(spec, comp, row)
        row["solid_s"] = f"{time.perf_counter() - t1:.2f}"
        if mesh:
            t2 = time.perf_counter()
            for comp in GEARS:
                stage = f"{comp} coarse mesh"
                failed += _check_mesh(spec, comp, row)
            row["mesh_s"] = f"{time.perf_counter() - t2:.2f}"
    except Exception as exc:  # noqa: BLE001  (a valid set that does not build is the finding)
        row.update(verdict="build_error", field="", detail=f"{stage}: {_last_line(exc)}")
        return row
    row.update(verdict="failed" if failed else "ok", field="", detail=" ".join(failed))
    return row


def _worker(conn, cache_root: str, files: str, mesh: bool, keep: bool) -> None:
    """Run the sets the parent sends, one at a time, each in its own cache subfolder; answer with its row."""
    import resource

    while True:
        s = conn.recv()
        if s is None:
            return
        cache = Path(cache_root) / f"set{s['set']:05d}"
        os.environ["FLEXGEAR_CACHE_DIR"] = str(cache)
        try:
            row = run_set(s, Path(files), mesh)
        except Exception as exc:  # noqa: BLE001
            row = {k: s[k] for k in PARAMS} | {"verdict": "internal_error", "detail": f"benchmark: {_last_line(exc)}"}
        row["peak_rss_mb"] = f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f}"
        if not keep:
            shutil.rmtree(cache, ignore_errors=True)
        conn.send(row)


# --------------------------------------------------------------------------- the run
class Worker:
    """One worker process (spawned: Netgen, OCC and BLAS single-threaded), restarted after a timeout or a crash."""

    def __init__(self, args) -> None:
        self.args, self.proc, self.conn = args, None, None

    def start(self) -> None:
        ctx = multiprocessing.get_context("spawn")
        self.conn, child = ctx.Pipe()
        self.proc = ctx.Process(target=_worker, args=(child, self.args.cache, self.args.files, self.args.mesh,
                                                      self.args.keep_cache), daemon=True)
        self.proc.start()
        child.close()

    def run(self, s: dict) -> dict:
        if self.proc is None or not self.proc.is_alive():
            self.start()
        self.conn.send(s)
        deadline = time.monotonic() + self.args.timeout
        while time.monotonic() < deadline:
            if self.conn.poll(1.0):
                try:
                    return self.conn.recv()
                except EOFError:
                    break
            if not self.proc.is_alive():
                break
        row = {k: s[k] for k in PARAMS}
        if self.proc.is_alive():
            row.update(verdict="timeout", detail=f"no answer within {self.args.timeout:g} s")
            self.proc.kill()
        else:
            row.update(verdict="crashed", detail=f"worker exit code {self.proc.exitcode}")
        self.proc.join()
        self.proc = None
        shutil.rmtree(Path(self.args.cache) / f"set{s['set']:05d}", ignore_errors=True)
        return row

    def stop(self) -> None:
        if self.proc is not None and self.proc.is_alive():
            self.conn.send(None)
            self.proc.join(30)
            if self.proc.is_alive():
                self.proc.kill()


def summary(rows: list[dict], wall: float) -> str:
    verdicts = Counter(r["verdict"] for r in rows)
    refused = Counter(r["field"] for r in rows if r["verdict"] == "refused")
    built = [r for r in rows if r["verdict"] in ("ok", "failed")]
    times = [float(r["wall_s"]) for r in rows]
    accepted = [float(r["wall_s"]) for r in built]
    lines = [f"sets tried: {len(rows)} in {wall:.0f} s ({np.mean(times) if times else 0:.2f} s per set; "
             f"{np.mean(accepted) if accepted else 0:.1f} s per built set, the longest "
             f"{max(accepted, default=0):.1f} s)",
             f"refused: {verdicts['refused']}"]
    for field, n in refused.most_common():
        lines.append(f"  {field}: {n}")
        reasons = Counter(_reason(r["detail"]) for r in rows if r["verdict"] == "refused" and r["field"] == field)
        lines += [f"    {count} x {reason}" for reason, count in reasons.most_common()]
    lines += [f"built (every gear's solid{' and coarse mesh' if any(r.get('mesh_s') for r in built) else ''}): "
              f"{len(built)}",
              f"checks passed: {verdicts['ok']} of {len(built)}; failed checks: {verdicts['failed']}",
              f"build errors of accepted sets: {verdicts['build_error']}; timeouts: {verdicts['timeout']}; "
              f"crashes: {verdicts['crashed']}",
              f"INTERNAL ERRORS: {verdicts['internal_error']}"]
    for r in rows:
        if r["verdict"] in ("internal_error", "build_error", "failed", "timeout", "crashed"):
            lines.append(f"  {r['verdict']} set {r['set']}: {_describe(r)}: {r.get('detail', '')}")
    for comp in GEARS:
        for key, unit in (("mass_err", ""), ("inertia_err", ""), ("flank_um", " um")):
            values = [float(r[f"{comp}_{key}"]) for r in built if r.get(f"{comp}_{key}")]
            if values:
                lines.append(f"worst {comp} {key}: {max(values):.3g}{unit}")
    return "\n".join(lines)


def _reason(detail: str) -> str:
    """A refusal's message without its numbers and the value it got: the kind of refusal."""
    text = re.sub(r", got .*$", "", detail.split(": ", 1)[-1])
    return re.sub(r"-?\d+(\.\d+)?(e-?\d+)?", "#", text)[:110]


def _describe(r: dict) -> str:
    helix = f"beta {r['helix_deg']} deg {r['kind']}" if r["kind"] != "spur" else "spur"
    return (f"{r['z_sun']}/{r['z_planet']}/{r['z_ring']}, {r['planets']} planets, m_n {r['module_mm']} mm, {helix}, "
            f"alpha_n {r['pressure_deg']} deg, x_planet {r['planet_shift']}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--count", type=int, default=300, help="sampled sets beside the corners")
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--no-corners", action="store_true", help="the sample only")
    ap.add_argument("--mesh", action=argparse.BooleanOptionalAction, default=True,
                    help="also each gear's coarse mesh (--no-mesh: solids only, faster)")
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds for one set")
    ap.add_argument("--first", type=int, default=0, help="start at this set (resume)")
    ap.add_argument("--limit", type=int, default=None, help="run at most this many sets")
    ap.add_argument("--time-limit", type=float, default=None,
                    help="start no further set after this many seconds (the summary covers the sets run)")
    ap.add_argument("--out", type=Path, default=Path("gear_set_grid.csv"))
    ap.add_argument("--files", type=Path, default=None, help="folder of the gearbox files (default: a temporary one)")
    ap.add_argument("--keep-cache", action="store_true", help="keep each set's solids and meshes")
    args = ap.parse_args(argv)
    if "FLEXGEAR_CACHE_DIR" not in os.environ:
        print("set FLEXGEAR_CACHE_DIR to a private folder", file=sys.stderr)
        return 2
    args.cache = os.environ["FLEXGEAR_CACHE_DIR"]
    args.files = str(args.files or tempfile.mkdtemp(prefix="gear_set_grid_"))
    Path(args.files).mkdir(parents=True, exist_ok=True)
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NGS_NUM_THREADS"):
        os.environ[var] = "1"  # inherited by the spawned worker

    sets = grid(args.count, args.seed, not args.no_corners)[args.first:]
    if args.limit is not None:
        sets = sets[:args.limit]
    print(f"{len(sets)} gear sets ({'solids and coarse meshes' if args.mesh else 'solids only'}), "
          f"files in {args.files}, rows to {args.out}", flush=True)
    worker, rows = Worker(args), []
    t_start = time.perf_counter()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with open(args.out, "w", newline="") as fh:
        writer = csv.DictWriter(fh, COLUMNS, extrasaction="ignore")
        writer.writeheader()
        try:
            for i, s in enumerate(sets, 1):
                t0 = time.perf_counter()
                if args.time_limit is not None and t0 - t_start > args.time_limit:
                    print(f"time limit {args.time_limit:g} s reached: {len(sets) - i + 1} sets not run", flush=True)
                    break
                row = worker.run(s)
                row["wall_s"] = f"{time.perf_counter() - t0:.2f}"
                rows.append(row)
                writer.writerow(row)
                fh.flush()
                what = row.get("field") if row["verdict"] == "refused" else row.get("detail", "")
                print(f"[{i}/{len(sets)} {time.perf_counter() - t_start:7.0f} s] set {s['set']} {_describe(row)}: "
                      f"{row['verdict']} {what or ''} ({row['wall_s']} s)", flush=True)
        finally:
            worker.stop()
    print()
    print(summary(rows, time.perf_counter() - t_start))
    return 0


if __name__ == "__main__":
    sys.exit(main())
