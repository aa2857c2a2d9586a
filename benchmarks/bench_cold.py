"""How long does a cold build take and how much memory does it need: the coarse meshes and reduced bodies of
every component (goal <= 90 s on the 2-core machine), a first ``make`` (goal <= 2 GB), and what each mesh
level gives (size, shape quality, mass against the exact solid)?

Run: nice -n 5 python benchmarks/bench_cold.py [--repeat 3] [--sections cold make meshes] [--make-target quick]
     nice -n 5 python benchmarks/bench_cold.py --sections meshes [--runs coarse coarse:2 default]
                                               [--components sun ring ...] [--keep DIR]

- cold: ``python -m flexgear.cli meshes --level coarse`` (OCC solids, Netgen meshes and reduced bodies
  of every component) in a fresh, empty temporary ``FLEXGEAR_CACHE_DIR``: wall time and the peak memory of the
  process tree;
- make: ``make <target> PY=<this python> RESULTS=<temporary folder>`` in the project folder, again with
  an empty cache folder (what a first ``make`` does): wall time and peak memory;
- meshes (once, not repeated): in a fresh cache folder, per component the solid is built
  (flexgear.fe.mesh.component_brep) and meshed at each of ``--runs`` (level, optionally ``:order``). One row
  per component and run: tetrahedra, nodes, solid time, mesh time (Netgen, from reading the ``.brep`` to the
  last node), the smallest shape quality of the vertex tetrahedra (mean ratio 12 (3V)^(2/3) / sum of squared
  edge lengths: 1 regular, 0 flat) and the mesh-vs-exact differences of mass and Izz
  (flexgear.fe.surface.mass_check); the solid's own OCC mass against the exact section integrals once per component.

CPU time is the sum over the command's processes (user + system; on a busy machine the steadier figure,
but parallel work counts once per core). Peak memory is the largest maximum resident set size among the
command's processes and their descendants (``getrusage(RUSAGE_CHILDREN)`` of a wrapper process that runs
only that command). With worker processes side by side the machine needs their sum, so the largest sum
over the command's process tree, sampled every 0.5 s (a shorter peak can be missed), is reported too, of
the resident sets (shared library pages counted once per process: an upper bound) and of the proportional
set sizes (each shared page split among the processes that map it: the memory the tree occupies).
Each round uses its own empty folders, removed afterwards.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from bench_speed import figure_line, load_average

ROOT = Path(__file__).resolve().parents[1]
_SAMPLE_S = 0.5  # s between memory samples (each sample reads /proc of every process: shorter costs CPU)
COMPONENTS = ("sun", "planet", "ring", "input_shaft", "output_shaft")


def _pss(pid: int) -> int:
    """Proportional set size [bytes] of process ``pid`` (Linux /proc/PID/smaps_rollup; 0 if it has ended)."""
    try:
        with open(f"/proc/{pid}/smaps_rollup") as f:
            for line in f:
                if line.startswith("Pss:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


def _command(pid: int) -> str:
    """The command line of process ``pid``, shortened ('' if it has ended)."""
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            return f.read().replace(b"\0", b" ").decode(errors="replace").strip()[:100]
    except OSError:
        return ""


def _tree_memory(root: int, parts: list | None = None) -> tuple[int, int]:
    """Sums of the resident sets and of the proportional set sizes [bytes] of process ``root`` and its
    descendants (Linux /proc); ``parts``, if given, receives (PSS [bytes], command line) of each of them."""
    parent, rss = {}, {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            parent[int(entry)], rss[int(entry)] = int(fields[1]), int(fields[21]) * os.sysconf("SC_PAGE_SIZE")
        except (OSError, IndexError, ValueError):
            continue  # the process ended meanwhile
    children: dict[int, list[int]] = {}
    for pid, ppid in parent.items():
        children.setdefault(ppid, []).append(pid)
    total_rss, total_pss, todo = 0, 0, [root]
    while todo:
        pid = todo.pop()
        total_rss += rss.get(pid, 0)
        pss = _pss(pid)
        total_pss += pss
        if parts is not None:
            parts.append((pss, _command(pid)))
        todo += children.get(pid, [])
    return total_rss, total_pss


def _child(cmd: list[str]) -> None:
    """Wrapper mode: run ``cmd``, print JSON with its wall time, exit code, peak RSS of its largest process
    and the largest sampled sum over its process tree [bytes]."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    peak_sum = [0, 0]
    at_peak: dict = {"t_s": 0.0, "processes": []}  # the process tree when the PSS sum peaked
    stop = threading.Event()

    def sample() -> None:
        while not stop.wait(_SAMPLE_S):
            parts: list = []
            now = _tree_memory(proc.pid, parts)
            if now[1] > peak_sum[1]:
                at_peak.update(t_s=time.perf_counter() - t0, processes=sorted(parts, reverse=True)[:6])
            peak_sum[:] = [max(p, m) for p, m in zip(peak_sum, now, strict=True)]

    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    stderr = proc.communicate()[1]
    wall = time.perf_counter() - t0
    stop.set()
    sampler.join()
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    tail = stderr.strip().splitlines()[-3:] if proc.returncode else []
    print(json.dumps({"wall_s": wall, "cpu_s": usage.ru_utime + usage.ru_stime, "returncode": proc.returncode,
                      "max_rss_bytes": usage.ru_maxrss * 1024, "tree_rss_bytes": peak_sum[0],
                      "tree_pss_bytes": peak_sum[1], "pss_peak": at_peak,
                      "stderr_tail": tail}))  # ru_maxrss: KiB (Linux)


def measure(cmd: list[str], cache_dir: Path) -> dict:
    """Run ``cmd`` through the wrapper with an empty ``FLEXGEAR_CACHE_DIR``; its wall time and peak RSS."""
    env = dict(os.environ, FLEXGEAR_CACHE_DIR=str(cache_dir))
    out = subprocess.run([sys.executable, __file__, "--child", *cmd], env=env, capture_output=True, text=True,
                         check=True)
    res = json.loads(out.stdout.strip().splitlines()[-1])
    if res["returncode"] != 0:
        sys.exit(f"{' '.join(cmd)} failed ({res['returncode']}): {res['stderr_tail']}")
    return res


def shape_quality(nodes, elements) -> float:
    """Smallest mean-ratio quality of the tetrahedra spanned by the first four nodes of each element."""
    import numpy as np

    p = nodes[elements[:, :4]]
    a, b, c = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]
    volume = np.abs(np.einsum("ij,ij->i", a, np.cross(b, c))) / 6
    edges2 = sum(np.sum((p[:, i] - p[:, j]) ** 2, axis=1) for i in range(4) for j in range(i + 1, 4))
    return float((12 * (3 * volume) ** (2 / 3) / edges2).min())


def mesh_table(a: argparse.Namespace) -> None:
    """The ``meshes`` section (module docstring), built in ``--keep`` or a temporary folder."""
    folder = Path(a.keep) if a.keep else Path(tempfile.mkdtemp(prefix="flexgear-bench-meshes-"))
    os.environ["FLEXGEAR_CACHE_DIR"] = str(folder)

    import netgen.occ as occ

    from flexgear.fe.mesh import component_brep, component_mesh
    from flexgear.fe.surface import mass_check
    from flexgear.geometry.layout import exact_mass_properties
    from flexgear.spec import load_gearbox

    spec = load_gearbox(a.gearbox)
    rho = spec.material_assumed.density_kg_m3
    print(f"meshes: cache folder {folder} (cold)", flush=True)
    header = (f"{'component':<13}{'level':<8}{'order':>5}{'tets':>9}{'nodes':>9}{'solid s':>9}{'mesh s':>8}"
              f"{'q_min':>7}{'mass err %':>12}{'Izz err %':>11}")
    rows = []
    try:
        for name in a.components:
            t0 = time.perf_counter()
            brep = component_brep(spec, name)
            t_solid = time.perf_counter() - t0
            shape = occ.OCCGeometry(str(brep)).shape
            exact = exact_mass_properties(spec, name)
            print(f"{name}: solid {t_solid:.1f} s, {len(shape.faces)} faces, OCC mass vs exact "
                  f"{100 * (rho * shape.mass / exact.mass - 1):+.5f} %", flush=True)
            for run in a.runs:
                level, _, order = run.partition(":")
                mesh = component_mesh(spec, name, level, order=int(order) if order else None)
                err = mass_check(spec, mesh)
                row = (f"{name:<13}{level:<8}{mesh.order:>5}{mesh.n_elements:>9}{mesh.n_nodes:>9}{t_solid:>9.1f}"
                       f"{mesh.build_time_s:>8.1f}{shape_quality(mesh.nodes, mesh.elements):>7.3f}"
                       f"{100 * err['mass']:>+12.4f}{100 * err['izz']:>+11.4f}")
                rows.append(row)
                print(row, flush=True)
    finally:
        if not a.keep:
            shutil.rmtree(folder, ignore_errors=True)
    print()
    print(header)
    print("\n".join(rows))


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        _child(sys.argv[2:])
        return
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--sections", nargs="+", default=["cold", "make"], choices=["cold", "make", "meshes"])
    ap.add_argument("--make-target", default="quick")
    ap.add_argument("--runs", nargs="+", default=["coarse", "coarse:2", "default"],
                    help="meshes: mesh level, optionally :order")
    ap.add_argument("--components", nargs="+", default=list(COMPONENTS), choices=COMPONENTS)
    ap.add_argument("--gearbox", default=str(ROOT / "model_variants" / "gearbox.toml"))
    ap.add_argument("--keep", help="meshes: build in this folder and keep it (default: a temporary folder, removed)")
    a = ap.parse_args()
    if "meshes" in a.sections:
        a.sections.remove("meshes")
        mesh_table(a)
        if not a.sections:
            return
    print(f"bench_cold: {a.repeat} rounds of {a.sections}; {load_average()}", flush=True)
    commands = {"cold": [sys.executable, "-m", "flexgear.cli", "meshes", "--level", "coarse"]}
    walls: dict[str, list[float]] = {s: [] for s in a.sections}
    cpus: dict[str, list[float]] = {s: [] for s in a.sections}
    rss: dict[str, list[float]] = {s: [] for s in a.sections}
    tree: dict[str, list[float]] = {s: [] for s in a.sections}
    tree_pss: dict[str, list[float]] = {s: [] for s in a.sections}
    for i in range(a.repeat):
        for section in a.sections:
            folder = Path(tempfile.mkdtemp(prefix=f"flexgear-bench-{section}-"))
            try:
                cmd = commands.get(section) or ["make", a.make_target, f"PY={sys.executable}",
                                                f"RESULTS={folder / 'results'}"]
                res = measure(cmd, folder / "cache")
            finally:
                shutil.rmtree(folder, ignore_errors=True)
            walls[section].append(res["wall_s"])
            cpus[section].append(res["cpu_s"])
            rss[section].append(res["max_rss_bytes"] / 1e9)
            tree[section].append(res["tree_rss_bytes"] / 1e9)
            tree_pss[section].append(res["tree_pss_bytes"] / 1e9)
            print(f"round {i + 1} {section}: wall {res['wall_s']:.1f} s, CPU {res['cpu_s']:.1f} s, "
                  f"peak RSS {rss[section][-1]:.2f} GB (largest process), sums over the processes: RSS "
                  f"{tree[section][-1]:.2f} GB, PSS {tree_pss[section][-1]:.2f} GB; {load_average()}", flush=True)
            peak = res["pss_peak"]
            print(f"  PSS sum peaked at {peak['t_s']:.1f} s: " + "; ".join(
                f"{pss / 1e9:.2f} GB {command}" for pss, command in peak["processes"]), flush=True)
    print()
    goals = {"cold": ("<= 90 s", ""), "make": ("", "<= 2 GB")}
    for section in a.sections:
        print(figure_line(f"{section} wall [s]", walls[section]) + f"   goal {goals[section][0] or '-'}")
        print(figure_line(f"{section} CPU, all processes [s]", cpus[section]))
        print(figure_line(f"{section} peak RSS, largest process [GB]", rss[section], "GB")
              + f"   goal {goals[section][1] or '-'}")
        print(figure_line(f"{section} peak RSS, sum over processes [GB]", tree[section], "GB"))
        print(figure_line(f"{section} peak PSS, sum over processes [GB]", tree_pss[section], "GB")
              + f"   goal {goals[section][1] or '-'}")
    print(f"after: {load_average()}")


if __name__ == "__main__":
    main()
