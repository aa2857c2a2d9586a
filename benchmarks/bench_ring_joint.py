"""The ring-output shaft joint against full FE: the first ten free-free modes of ring + output shaft.

    python benchmarks/bench_ring_joint.py [--level coarse] [--gearbox model_variants/gearbox.toml]
                                          [--clamp-diameter-mm D]

Full FE (flexgear.fe.bolted): the ring's and the output shaft's meshes, the web face tied to the flange face
over each bolt's clamped disc (``[joints_assumed] bolt_clamp_diameter_mm``) by multipoint constraints.
Reduced (flexgear.fe.joined): the two reduced bodies as the multibody model builds them, joined

- "RBE3": one RBE3 interface over all 12 bolt-hole walls of each body, one fixed joint at the bolt circle;
- "bolt patches (rigid)": per bolt a rigid patch (RBE2) over its clamped disc on each face, joined pairwise;
- "bolt patches (RBE3)": the same discs as RBE3 patches.

Prints per mode the full FE frequency, each variant's and its error [%], then each variant's largest error
against the 5 % criterion of issue 13. The reduced bodies are cached (FLEXGEAR_CACHE_DIR); the full FE
eigenproblem (about 3e5 coordinates at the coarse level) takes about a minute and 4 GB.
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

VARIANTS = {"RBE3": ("rbe3", "rbe2"), "bolt patches (rigid)": ("bolt_patches", "rbe2"),
            "bolt patches (RBE3)": ("bolt_patches", "rbe3")}
CRITERION = 0.05  # issue 13: first ten modes within 5 % of full FE
N_MODES = 10


def main() -> None:
    from flexgear.fe.bolted import ring_output_shaft_fe_modes
    from flexgear.fe.joined import ring_output_shaft_modes
    from flexgear.spec import load_gearbox

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", default="coarse")
    parser.add_argument("--gearbox", default="model_variants/gearbox.toml")
    parser.add_argument("--clamp-diameter-mm", type=float, default=None,
                        help="override [joints_assumed] bolt_clamp_diameter_mm (both models)")
    args = parser.parse_args()
    spec = load_gearbox(args.gearbox)
    if args.clamp_diameter_mm is not None:
        spec = spec.with_changes(joints_assumed=dataclasses.replace(
            spec.joints_assumed, bolt_clamp_diameter_mm=args.clamp_diameter_mm))
    t0 = time.perf_counter()
    full = ring_output_shaft_fe_modes(spec, args.level, N_MODES)
    print(f"full FE ({args.level}, clamp discs {spec.joints_assumed.bolt_clamp_diameter_mm} mm): "
          f"{time.perf_counter() - t0:.1f} s")
    freqs = {}
    for label, (joint, patch) in VARIANTS.items():
        t0 = time.perf_counter()
        joints = dataclasses.replace(spec.joints_assumed, ring_output_shaft=joint, bolt_patch=patch)
        freqs[label] = ring_output_shaft_modes(spec, joints, args.level, N_MODES, progress=True)
        print(f"{label}: {time.perf_counter() - t0:.1f} s (reduced bodies cached after the first run)")
    head = f"{'mode':>4} {'full FE Hz':>11}" + "".join(f" {label + ' Hz':>25} {'err %':>7}" for label in freqs)
    print(head)
    for m in range(N_MODES):
        row = f"{m + 1:>4} {full[m]:>11.1f}"
        for f in freqs.values():
            row += f" {f[m]:>25.1f} {100 * (f[m] / full[m] - 1):>+7.2f}"
        print(row)
    for label, f in freqs.items():
        worst = float(np.max(np.abs(f / full - 1)))
        verdict = "meets" if worst <= CRITERION else "misses"
        print(f"{label}: largest error {100 * worst:.2f} %, {verdict} the {100 * CRITERION:.0f} % criterion")


if __name__ == "__main__":
    main()
