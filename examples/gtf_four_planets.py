"""The GTF star gearbox of the reference study with 4 planets instead of 5.

Equally spaced planets need (z_s + z_r) / N to be an integer: (44 + 136) / 4 = 45. Everything else is
the study's gearbox (model_variants/gearbox.toml, model 1: all rigid), changed only through
``GearboxSpec.with_changes``; the same public builder (``run_variant`` -> ``build_star_gearbox``)
assembles it. Theory: ring / sun speed = -z_s / z_r; normal mesh force per planet
F = T_sun / (N r_b,sun cos beta_b), 5/4 of the five-planet value.

Run: python examples/gtf_four_planets.py  (ramps over 0.04 s, 0.25 s simulated, ~10 s wall time)
"""

import dataclasses
from pathlib import Path

import flexgear as fg

ROOT = Path(__file__).resolve().parents[1]
PLANETS = 4


def variant(planets: int = PLANETS, ramp_time_s: float = 0.04, end_time_s: float = 0.25) -> fg.Variant:
    """Model 1 of the study with ``planets`` planets and a shortened load case."""
    v = fg.load_variant(ROOT / "model_variants" / "model1.toml")
    g = v.gearbox
    if (g.gears.sun_teeth + g.gears.ring_teeth) % planets:
        raise ValueError(f"{planets} planets cannot be equally spaced: (z_s + z_r) / N must be an integer")
    g = g.with_changes(gears=dataclasses.replace(g.gears, planet_count=planets),
                       load_case=dataclasses.replace(g.load_case, ramp_time_s=ramp_time_s, end_time_s=end_time_s))
    # rigid bodies with the exact geometry's mass properties: no meshes or reduced bodies to build
    return dataclasses.replace(v, name=f"{v.name}_{planets}_planets", gearbox=g, rigid_mass_properties="exact")


def main(planets: int = PLANETS, t_end: float = 0.25, progress: bool = False):
    """Run the variant; returns the run result (signals, metadata with the theory values)."""
    result = fg.run_variant(variant(planets, end_time_s=t_end), progress=progress)
    if not result.ok:
        raise RuntimeError(result.meta["reason"])
    return result


if __name__ == "__main__":
    r = main(progress=True)
    s, th = r.signals, r.meta["theory"]
    late = s[s.time_s >= 0.8 * s.time_s.iloc[-1]]
    print(f"speed ratio ring/sun {late.transmission_ratio.mean():.6f} (theory {th['ratio']:.6f})")
    for i in range(1, PLANETS + 1):
        print(f"planet {i}: outer {late[f'outer_mesh_force_{i}_n'].mean():.2f} N, inner "
              f"{late[f'inner_mesh_force_{i}_n'].mean():.2f} N (theory {th['mesh_force_n']:.2f} N)")
