"""A single helical gear pair: rigid pinion driven, flexible toothed wheel loaded.

Built from flexgear's public API only. Gear data (assumed for this example): pinion 20, wheel 50 teeth,
normal module 3 mm, helix 15 deg, normal pressure angle 20 deg, 25 mm face width, single helix, no profile
shift, 0.1 mm backlash, 40 mm bores. Both gears are toothed bodies (fg.GearBody) built as the GTF study builds
its gears: the pinion is rigid with the exact mass properties of its toothed section (fg.toothed_mass_properties);
the wheel is a reduced flexible body of its meshed toothed solid (fg.toothed_body: second-order tetrahedra,
Craig-Bampton on its bore with every fixed-interface mode below 20 kHz and the attachment modes of its contact
band). Its modes below 8 kHz are integrated; the others return as a static residual compliance in series with the
contact law (fg.dropped_modes). The wheel's body is cached under meshes/ (about 30 s to build once).
Contact law: the GTF study's values (model_variants/gearbox.toml), with less damping to settle in a short run.
Theory: wheel / pinion speed = -z1/z2; normal mesh force F = T_wheel / (r_b,wheel cos beta_b).

Run: python examples/helical_pair_flexible.py  (0.1 s simulated, ~10 s wall time once the wheel is cached)
"""

import dataclasses
import math
from pathlib import Path

import numpy as np

import flexgear as fg

ROOT = Path(__file__).resolve().parents[1]
Z_PINION, Z_WHEEL = 20, 50
MODULE_M, HELIX_DEG, PRESSURE_DEG, WIDTH_M, BORE_DIAMETER_M = 3e-3, 15.0, 20.0, 0.025, 0.04
INPUT_SPEED_RPM, LOAD_TORQUE_NM = 3000.0, 150.0  # pinion speed, load torque on the wheel
# Each gear on a shaft with two bearings 100 mm apart (2e8 N/m radial each): tilt stiffness
# 2 * 2e8 * 0.05^2 = 1e6 N m/rad, so the helical mesh's tilting moment tilts the gears by ~1e-4 rad.
RADIAL_N_PER_M, AXIAL_N_PER_M, TILT_NM_PER_RAD, DAMPING_PER_STIFFNESS_S = 4e8, 2e7, 1e6, 1e-5
RAMP_S, STEP_S = 0.02, 1e-5
DAMPING_FRACTION = 2e-4  # of the contact stiffness (study: 1e-3); settles within this short run
CUTOFF_HZ = 20e3
"""Fixed-interface modes of the wheel's reduction: every one below. The study's 3.5 x the mesh frequency would
leave the wheel's third free mode (7.5 kHz) 4 % high even with 15 kHz (tests/test_toothed_body.py)."""
KEEP_BELOW_HZ = 8e3
"""The wheel's modes integrated in time (8 mesh orders); the others return as residual compliance."""


def gear_bodies(spec) -> tuple[fg.GearMesh, fg.GearBody, fg.GearBody, fg.Engagement]:
    """The mesh (pinion gear 1, wheel gear 2), both toothed bodies and the wheel's engagement: the pinion, of
    hand +1, drives the wheel counter-clockwise; the wheel at +x meets it at polar angle pi."""
    mesh = fg.gear_pair_geometry(Z_PINION, Z_WHEEL, MODULE_M, math.radians(HELIX_DEG), math.radians(PRESSURE_DEG),
                                 WIDTH_M, normal_backlash=1e-4)
    common = dict(bore_diameter=BORE_DIAMETER_M, helix_layout="single", material=spec.material_assumed)
    pinion = fg.GearBody.from_gear(mesh.gear1, name="pinion", hand=1, **common)
    wheel = fg.GearBody.from_gear(mesh.gear2, name="wheel", hand=-1, **common)
    return mesh, pinion, wheel, fg.Engagement(mesh, gear=2, drive_sign=1, angles=(math.pi,))


def wheel_body(spec, wheel: fg.GearBody, engagement: fg.Engagement, progress: bool = False) -> fg.ReducedBody:
    """The wheel's reduced flexible body (cached), attachment modes to the study's order."""
    return fg.toothed_body(wheel, [engagement], cutoff_hz=CUTOFF_HZ,
                           attachment_order=spec.reduction_assumed.attachment_order, progress=progress)


def build(mbs, spec, progress: bool = False):
    """Bodies, bearings, contact, drive and load; returns handles and the theory."""
    mesh, pinion_gear, wheel_gear, engagement = gear_bodies(spec)
    centre2 = np.array([mesh.centre_distance, 0.0, 0.0])
    pinion = fg.add_rigid_body(mbs, "pinion", fg.toothed_mass_properties(pinion_gear), np.zeros(3))
    w_in = INPUT_SPEED_RPM * 2 * math.pi / 60
    full = wheel_body(spec, wheel_gear, engagement, progress)
    keep = full.modes_below(KEEP_BELOW_HZ)
    # linear floating frame at the wheel's nominal spin; the SpinSchedule moves its spin terms with the ramp
    wheel = fg.add_flexible_body(mbs, "wheel", full.truncated(keep), centre2,
                                 stiffness_damping_s=spec.reduction_assumed.modal_stiffness_damping_s,
                                 interface_markers=[], show=False, nominal_spin_rad_s=-w_in * Z_PINION / Z_WHEEL)
    wheel = dataclasses.replace(wheel, dropped=fg.dropped_modes(spec, full, keep, "wheel"))
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
    g2 = mesh.gear2
    theory = {"ratio": -Z_PINION / Z_WHEEL, "input_torque_nm": LOAD_TORQUE_NM * Z_PINION / Z_WHEEL,
              "mesh_force_n": LOAD_TORQUE_NM / (g2.base_radius * math.cos(g2.base_helix_angle)),
              "wheel_modes_kept": keep, "wheel_modes": full.n_modes}
    return {"pinion": pinion, "wheel": wheel}, train, drive, theory


def main(t_end: float = 0.1, progress: bool = False):
    """Run the pair; returns the signal table and the theory values."""
    import exudyn as exu

    spec = fg.load_gearbox(ROOT / "model_variants" / "gearbox.toml")
    mbs = exu.SystemContainer().AddSystem()
    by, train, drive, theory = build(mbs, spec, progress)
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
    print(f"wheel: {th['wheel_modes_kept']} of {th['wheel_modes']} modes integrated, the others as residual compliance")
    print(f"speed ratio wheel/pinion {late.ratio.mean():.6f} (theory {th['ratio']:.6f})")
    print(f"mesh force {late.mesh_force_n.mean():.2f} N (theory {th['mesh_force_n']:.2f} N), "
          f"input torque {late.input_torque_nm.mean():.3f} N m (theory {th['input_torque_nm']:.3f})")
