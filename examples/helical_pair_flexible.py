"""A single helical gear pair: rigid pinion driven, flexible wheel loaded.

Built from flexgear's public API only. Gear data (assumed for this example): pinion 20, wheel 50 teeth,
normal module 3 mm, helix 15 deg, normal pressure angle 20 deg, 25 mm face width, no profile shift,
0.1 mm backlash. The wheel is a reduced flexible body (Craig-Bampton, distributing bore interface)
of a plain annulus from its bore to the reference circle (a coarse stand-in for the toothed wheel:
the tooth compliance lives in the contact law). Contact law: the GTF study's values
(model_variants/gearbox.toml), with less damping to settle in a short run. Theory: wheel / pinion
speed = -z1/z2; normal mesh force F = T_wheel / (r_b,wheel cos beta_b).

Run: python examples/helical_pair_flexible.py  (0.1 s simulated, ~10 s wall time)
"""

import dataclasses
import math
from pathlib import Path

import numpy as np

import flexgear as fg

ROOT = Path(__file__).resolve().parents[1]
Z_PINION, Z_WHEEL = 20, 50
MODULE_M, HELIX_DEG, PRESSURE_DEG, WIDTH_M, BORE_M = 3e-3, 15.0, 20.0, 0.025, 0.02
INPUT_SPEED_RPM, LOAD_TORQUE_NM = 3000.0, 150.0  # pinion speed, load torque on the wheel
# Each gear on a shaft with two bearings 100 mm apart (2e8 N/m radial each): tilt stiffness
# 2 * 2e8 * 0.05^2 = 1e6 N m/rad, so the helical mesh's tilting moment tilts the gears by ~1e-4 rad.
RADIAL_N_PER_M, AXIAL_N_PER_M, TILT_NM_PER_RAD, DAMPING_PER_STIFFNESS_S = 4e8, 2e7, 1e6, 1e-5
RAMP_S, STEP_S = 0.02, 1e-5
DAMPING_FRACTION = 2e-4  # of the contact stiffness (study: 1e-3); settles within this short run


def wheel_body(spec, mesh: fg.GearMesh, modes: int = 12) -> fg.ReducedBody:
    """Reduced flexible body of the wheel: annulus bore..reference radius, first-order tets, 8 mm."""
    import ngsolve as ngs
    from netgen.occ import Cylinder, OCCGeometry, Pnt, Z

    r_out, h = mesh.gear2.reference_radius, WIDTH_M
    solid = Cylinder(Pnt(0, 0, -h / 2), Z, r=r_out, h=h) - Cylinder(Pnt(0, 0, -h / 2), Z, r=BORE_M, h=h)
    fe = fg.fe_model(ngs.Mesh(OCCGeometry(solid).GenerateMesh(maxh=0.008)), spec.material_assumed, order=1)
    bore = np.flatnonzero(np.abs(np.hypot(fe.nodes[:, 0], fe.nodes[:, 1]) - BORE_M) < 1e-6)
    return fg.reduce(fe, [fg.interface(fe, bore, "bore")], 20, n_compare=0).truncated(modes)


def build(mbs, spec):
    """Bodies, bearings, contact, drive and load; returns handles and the theory."""
    mesh = fg.gear_pair_geometry(Z_PINION, Z_WHEEL, MODULE_M, math.radians(HELIX_DEG), math.radians(PRESSURE_DEG),
                                 WIDTH_M, normal_backlash=1e-4)
    centre2 = np.array([mesh.centre_distance, 0.0, 0.0])
    rho = spec.material_assumed.density_kg_m3
    pinion = fg.add_rigid_body(mbs, "pinion", fg.annulus_mass_properties(BORE_M / 2, mesh.gear1.reference_radius,
                                                                         WIDTH_M, rho), np.zeros(3))
    w_in = INPUT_SPEED_RPM * 2 * math.pi / 60
    # linear floating frame at the wheel's nominal spin; the SpinSchedule moves its spin terms with the ramp
    wheel = fg.add_flexible_body(mbs, "wheel", wheel_body(spec, mesh), centre2,
                                 stiffness_damping_s=spec.reduction_assumed.modal_stiffness_damping_s,
                                 interface_markers=[], show=False, nominal_spin_rad_s=-w_in * Z_PINION / Z_WHEEL)
    spin = fg.SpinSchedule(mbs, [wheel], RAMP_S, spec.solver_assumed.spin_update_interval_s)
    contact = dataclasses.replace(spec.contact, damping_fraction_of_stiffness=DAMPING_FRACTION)
    contacts = fg.pair_contacts("mesh", "pinion", "wheel", mesh, np.zeros(3), centre2, contact,
                                spec.contact_assumed, hand=1, drive_sign=1.0)
    bushings = [fg.BearingElement.axisymmetric(name, RADIAL_N_PER_M, AXIAL_N_PER_M, TILT_NM_PER_RAD,
                                               DAMPING_PER_STIFFNESS_S) for name in ("pinion", "wheel")]
    train = fg.add_gear_train(mbs, [pinion, wheel], bushings, contacts, RAMP_S, w_in, extra_pre_steps=[spin],
                              contact_fourier_order=spec.reduction_assumed.contact_fourier_order,
                              radial_band=MODULE_M)
    drive = fg.add_speed_drive(mbs, pinion, RAMP_S, w_in)
    fg.add_load_torque(mbs, wheel, LOAD_TORQUE_NM, RAMP_S)  # the wheel turns clockwise: load counter-clockwise
    wheel_gear = mesh.gear2
    theory = {"ratio": -Z_PINION / Z_WHEEL, "input_torque_nm": LOAD_TORQUE_NM * Z_PINION / Z_WHEEL,
              "mesh_force_n": LOAD_TORQUE_NM / (wheel_gear.base_radius * math.cos(wheel_gear.base_helix_angle))}
    return {"pinion": pinion, "wheel": wheel}, train, drive, theory


def main(t_end: float = 0.1, progress: bool = False):
    """Run the pair; returns the signal table and the theory values."""
    import exudyn as exu

    spec = fg.load_gearbox(ROOT / "model_variants" / "gearbox.toml")
    mbs = exu.SystemContainer().AddSystem()
    by, train, drive, theory = build(mbs, spec)
    rec = fg.Recorder(mbs)
    rec.speed("pinion", by["pinion"])
    rec.speed("wheel", by["wheel"])
    rec.drive_torque("input", drive)
    rec.mesh_force("mesh", train.springs)
    signals = fg.solve(mbs, t_end, STEP_S, rec, progress=progress)
    signals["ratio"] = signals.wheel_speed_rad_per_s / signals.pinion_speed_rad_per_s
    return signals, theory


if __name__ == "__main__":
    s, th = main(progress=True)
    late = s[s.time_s >= 0.8 * s.time_s.iloc[-1]]
    print(f"speed ratio wheel/pinion {late.ratio.mean():.6f} (theory {th['ratio']:.6f})")
    print(f"mesh force {late.mesh_force_n.mean():.2f} N (theory {th['mesh_force_n']:.2f} N), "
          f"input torque {late.input_torque_nm.mean():.3f} N m (theory {th['input_torque_nm']:.3f})")
