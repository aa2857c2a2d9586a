"""Measurements behind the flexible-physics issue's multibody half: supports, ISO 6336 law, ripple, deflections.

Run: python benchmarks/bench_flexible_physics.py [sharing|ripple|all] [--t-end 0.1]

- ``sharing``: rigid model 1 (exact mass properties) and the lumped model, law = "iso6336" and "impact", bearings
  at the gear centres and at their seats: mesh-force ripple, dynamic load-sharing factor K_gamma (time mean of
  max/mean over the planets), bearing acceleration at 1x mesh frequency, loaded transmission error; then the
  lumped model's static load sharing with a 10 um tangential pin-position error of planet 1.
- ``ripple``: law = "iso6336", model 1 and model 4 at h and h/2: inner/outer mesh-force ripple (rss of the 1x-3x
  mesh-frequency amplitudes, mean over the planets), mean forces, TE and the flexible gears' deflections.
Ramps over 0.02 s; every value is taken from t_end/2 on.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time

import numpy as np

from flexgear.lumped.run import _LOAD_SIGN, _OUT_SPIN, _T_LOAD, build_lumped_model, run_lumped
from flexgear.mbs.run import run_variant
from flexgear.spec import SupportsAssumed, load_variant
from flexgear.study.compare import harmonic_amplitudes
from flexgear.theory import theory


def _variant(name: str, law: str, t_end: float, placement: str = "bearing_seats", step: float | None = None,
             exact: bool = False):
    v = load_variant(f"model_variants/{name}.toml")
    gb = v.gearbox
    lc = dataclasses.replace(gb.load_case, ramp_time_s=0.02, end_time_s=t_end,
                             step_size_s=step or gb.load_case.step_size_s)
    gb = gb.with_changes(contact=dataclasses.replace(gb.contact, law=law), load_case=lc,
                         supports_assumed=SupportsAssumed(placement))
    return dataclasses.replace(v, gearbox=gb, rigid_mass_properties="exact" if exact else v.rigid_mass_properties)


def indicators(gb, signals, t_from: float) -> dict[str, float]:
    """Ripple, K_gamma, mean forces, 1x bearing accelerations, TE and deflections from ``t_from`` on."""
    w = signals[signals.time_s >= t_from]
    f_mesh, h = theory(gb).mesh_frequency, gb.load_case.step_size_s
    out = {}
    for kind in ("outer", "inner"):
        f = np.stack([w[f"{kind}_mesh_force_{i}_n"].to_numpy() for i in range(1, 6)])
        out[f"{kind}_mean_n"] = f.mean()
        out[f"{kind}_ripple_n"] = np.mean([np.sqrt(np.sum(harmonic_amplitudes(x, h, f_mesh, (1, 2, 3)) ** 2))
                                           for x in f])
        out[f"{kind}_k_gamma"] = float((f.max(0) / f.mean(0)).mean())
    for side in ("input", "output"):
        x = w[f"{side}_bearing_accel_x_m_per_s2"].to_numpy()
        out[f"{side}_accel_1x_m_per_s2"] = harmonic_amplitudes(x, h, f_mesh, (1,))[0]
    for c in w.columns:
        if c == "transmission_error_m" or ("deflection" in c and c.endswith("_1_m")):
            out[c] = w[c].mean()
    return {k: float(v) for k, v in out.items()}


def static_sharing_with_pin_error(gb, error_m: float = 10e-6) -> tuple[np.ndarray, np.ndarray]:
    """Lumped static mesh forces (sun, ring meshes) at full load with planet 1's pin moved ``error_m`` tangentially."""
    m = build_lumped_model(gb)
    s = m.system
    f = np.zeros(s.n)
    f[m.ip[_OUT_SPIN]] = m.fp[_LOAD_SIGN] * m.fp[_T_LOAD]
    psi = s.params.angles[0]
    f[9:11] += s.params.planet.bearing_stiffness_n_per_m * error_m * np.array([-np.sin(psi), np.cos(psi)])
    k, q, free = s.stiffness(), np.zeros(s.n), m.free
    q[free] = np.linalg.solve(k[np.ix_(free, free)], f[free])
    forces = s.mesh_stiffness * (s.mesh_G @ q)
    n = s.params.planet_count
    return forces[:n], forces[n:]


def sharing(t_end: float) -> None:
    for law in ("iso6336", "impact"):
        for placement in ("gear_centres", "bearing_seats"):
            v = _variant("model1", law, t_end, placement, exact=True)
            for name, r in (("model1", run_variant(v)), ("lumped", run_lumped(v.gearbox))):
                vals = indicators(v.gearbox, r.signals, t_end / 2)
                print(law, placement, name, {k: round(x, 9 if k.endswith("_m") else 4) for k, x in vals.items()},
                      flush=True)
            outer, inner = static_sharing_with_pin_error(v.gearbox)
            print(law, placement, "lumped static, 10 um pin error of planet 1: sun-mesh forces",
                  np.round(outer, 1), f"K_gamma {outer.max() / outer.mean():.4f}",
                  f"(ring meshes {inner.max() / inner.mean():.4f})", flush=True)


def ripple(t_end: float) -> None:
    for name in ("model1", "model4"):
        for step in (1e-5, 0.5e-5):
            v = _variant(name, "iso6336", t_end, step=step)
            c0 = time.process_time()
            r = run_variant(v)
            if not r.ok:
                print(name, step, "FAILED", r.meta["reason"], flush=True)
                continue
            vals = indicators(v.gearbox, r.signals, t_end / 2)
            print(name, step, f"cpu {time.process_time() - c0:.1f} s",
                  {k: round(x, 12 if k.endswith("_m") else 4) for k, x in vals.items()}, flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("what", nargs="?", default="all", choices=("sharing", "ripple", "all"))
    ap.add_argument("--t-end", type=float, default=0.1)
    a = ap.parse_args()
    if a.what in ("sharing", "all"):
        sharing(a.t_end)
    if a.what in ("ripple", "all"):
        ripple(a.t_end)


if __name__ == "__main__":
    sys.exit(main())
