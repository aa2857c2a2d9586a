"""A planetary stage with a rotating carrier: sun input, ring fixed, carrier output, 3 planets.

Built from flexgear's public API only (no package module edited). Gear data (assumed for this
example): sun 24, planets 30, ring 84 teeth (z_r = z_s + 2 z_p: one standard centre distance, no
profile shift), normal module 2 mm, helix 20 deg, normal pressure angle 20 deg, 30 mm face width,
single helical. Bearings, contact law, friction and stiffness variation: the GTF study's values
(model_variants/gearbox.toml). Theory: carrier speed / sun speed = z_s / (z_s + z_r) = 2/9; the
normal mesh force per planet F = T_sun / (N r_b,sun cos beta_b), T_sun = T_out z_s / (z_s + z_r).

Run: python examples/planetary_stage.py  (0.15 s simulated, ~10 s wall time)
"""

import dataclasses
import math
from pathlib import Path

import numpy as np

import flexgear as fg

ROOT = Path(__file__).resolve().parents[1]
Z_SUN, Z_PLANET, Z_RING, N_PLANETS = 24, 30, 84, 3
INPUT_SPEED_RPM, LOAD_TORQUE_NM = 3000.0, 300.0  # sun speed, load torque on the carrier
RAMP_S, STEP_S = 0.03, 1e-5
DAMPING_FRACTION = 2e-4  # of the contact stiffness (study: 1e-3); settles within this short run


def build(mbs, spec):
    """Bodies, bearings, contacts, drive and load of the stage; returns handles and the theory."""
    mn, beta, alpha_n, width = 2e-3, math.radians(20.0), math.radians(20.0), 0.03
    pair = dict(normal_module=mn, helix_angle=beta, pressure_angle=alpha_n, face_width=width, normal_backlash=1e-4)
    sun_planet = fg.gear_pair_geometry(Z_SUN, Z_PLANET, **pair)
    planet_ring = fg.gear_pair_geometry(Z_PLANET, Z_RING, internal=True, **pair)
    a = sun_planet.centre_distance
    assert math.isclose(a, planet_ring.centre_distance), "sun-planet and planet-ring centre distances differ"
    rho = spec.material_assumed.density_kg_m3
    sun, planet, ring = sun_planet.gear1, sun_planet.gear2, planet_ring.gear2
    bodies = [
        fg.add_rigid_body(mbs, "sun", fg.annulus_mass_properties(0.015, sun.reference_radius, width, rho), np.zeros(3)),
        fg.add_rigid_body(mbs, "ring", fg.annulus_mass_properties(ring.reference_radius, ring.root_radius + 0.008,
                                                                 width, rho), np.zeros(3)),
        fg.add_rigid_body(mbs, "carrier", fg.annulus_mass_properties(0.02, a + 0.03, 0.015, rho), np.zeros(3)),
    ]
    psi = 2 * math.pi * np.arange(N_PLANETS) / N_PLANETS
    centres = [a * np.array([math.cos(p), math.sin(p), 0.0]) for p in psi]
    for i, c in enumerate(centres):
        props = fg.annulus_mass_properties(0.012, planet.reference_radius, width, rho)
        bodies.append(fg.add_rigid_body(mbs, f"planet{i + 1}", props, c))
    by = {b.name: b for b in bodies}
    # kinematics per drive (sun) angle: carrier z_s/(z_s+z_r); planet spin from rolling in the carrier frame
    ratio = Z_SUN / (Z_SUN + Z_RING)
    w_planet = ratio - Z_SUN / Z_PLANET * (1.0 - ratio)
    contact = dataclasses.replace(spec.contact, damping_fraction_of_stiffness=DAMPING_FRACTION)
    common = dict(contact=contact, contact_assumed=spec.contact_assumed, carrier_spin=ratio)
    contacts = []
    for i, c in enumerate(centres):
        phase = Z_SUN * psi[i] / (2 * math.pi)  # sequential mesh phasing of the planets
        contacts += fg.pair_contacts(f"sun_planet{i + 1}", "sun", f"planet{i + 1}", sun_planet, np.zeros(3), c,
                                     hand=1, drive_sign=1.0, spins=(1.0, w_planet), phase_offset=phase, **common)
        contacts += fg.pair_contacts(f"planet_ring{i + 1}", f"planet{i + 1}", "ring", planet_ring, c, np.zeros(3),
                                     hand=-1, drive_sign=-1.0, spins=(w_planet, 0.0), phase_offset=phase, **common)
    b = spec.bearings
    bushings = [fg.BearingElement.from_bearing(bearing, body) for bearing, body in
                ((b.input_shaft, "sun"), (b.output_shaft, "ring"), (b.output_shaft, "carrier"))]
    w_in = INPUT_SPEED_RPM * 2 * math.pi / 60
    train = fg.add_gear_train(mbs, bodies, bushings, contacts, RAMP_S, w_in,
                              carrier=fg.Carrier("carrier", ratio))
    for i in range(N_PLANETS):
        fg.add_planet_bearing(mbs, by["carrier"], by[f"planet{i + 1}"],
                              fg.BearingElement.from_bearing(b.planet, f"planet{i + 1}", other="carrier"))
    fg.add_fixed_joint(mbs, by["ring"], coordinates=(5,))  # ring held against spinning
    drive = fg.add_speed_drive(mbs, by["sun"], RAMP_S, w_in)
    fg.add_load_torque(mbs, by["carrier"], -LOAD_TORQUE_NM, RAMP_S)
    t_sun = LOAD_TORQUE_NM * ratio
    theory = {"ratio": ratio, "input_torque_nm": t_sun,
              "mesh_force_n": t_sun / (N_PLANETS * sun.base_radius * math.cos(sun.base_helix_angle))}
    return by, train, drive, theory


def main(t_end: float = 0.15, progress: bool = False):
    """Run the stage; returns the signal table and the theory values."""
    import exudyn as exu

    spec = fg.load_gearbox(ROOT / "model_variants" / "gearbox.toml")
    mbs = exu.SystemContainer().AddSystem()
    by, train, drive, theory = build(mbs, spec)
    rec = fg.Recorder(mbs)
    rec.speed("sun", by["sun"])
    rec.speed("carrier", by["carrier"])
    rec.drive_torque("input", drive)
    for i in range(1, N_PLANETS + 1):
        rec.mesh_force(f"sun_planet{i}", train.springs_named(f"sun_planet{i}_"))
        rec.mesh_force(f"planet_ring{i}", train.springs_named(f"planet_ring{i}_"))
    signals = fg.solve(mbs, t_end, STEP_S, rec, progress=progress)
    signals["ratio"] = signals.carrier_speed_rad_per_s / signals.sun_speed_rad_per_s
    return signals, theory


if __name__ == "__main__":
    s, th = main(progress=True)
    late = s[s.time_s >= 0.8 * s.time_s.iloc[-1]]
    print(f"speed ratio carrier/sun {late.ratio.mean():.6f} (theory {th['ratio']:.6f})")
    for i in range(1, N_PLANETS + 1):
        print(f"planet {i}: sun-planet {late[f'sun_planet{i}_force_n'].mean():.2f} N, planet-ring "
              f"{late[f'planet_ring{i}_force_n'].mean():.2f} N (theory {th['mesh_force_n']:.2f} N)")
