"""The spur planetary example (examples/spur_planetary/: 24/30/84, 3 planets, ring fixed, carrier output) with
flexible gears on the turning carrier, and a flexible carrier.

Loss-free hand theory, independent of the package (the carrier's torque T_c, its speed Omega_c = Omega_in z_s /
(z_s + z_r), N planets on the centre distance a_w):

- ratio Omega_c / Omega_in = z_s / (z_s + z_r); every mesh's mean normal force F_n = T_sun / (N r_b,sun cos beta_b),
  T_sun = T_c z_s / (z_s + z_r) (tooth friction, mu = 0.02, moves the means by a few tenths of a percent: 1 %);
- without friction, each planet's bearing on its pin carries, in the carrier's axes, the tangential force
  T_c / (N a_w) (the planet's share of the carrier torque) and the radial force m_p Omega_c^2 a_w (the planet's
  orbit, m_p its mass): its two mesh forces' radial parts cancel on a spur planet with equal operating pressure
  angles; the sun's joint to its shaft carries T_sun, the ring's joint to the housing T_c z_r / (z_s + z_r) and the
  output shaft's joint to the carrier T_c.

The flexible planets sit on their pins through their bores' motion (flexgear.mbs.joints.LinearSeat with a carrier),
their contact columns follow their spin relative to the carrier; the flexible ring is held at its bolts' clamped
discs, and the flexible output shaft is bolted to the carrier at its own. The flexible carrier carries the planets'
bearings on its pins' nodes (flexgear.mbs.carrier.CarrierPins): its pins' deflection is checked against its static
compliance under the run's own bearing loads, its linear model against the reference formulation, its harmonic
response against its time run. The production formulation is checked against the reference formulation (Exudyn's
nonlinear floating frame) on the turning carrier as well. Every body is built in the examples' cache
(conftest.example_cache) from coarse meshes (about two minutes of CPU).
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from test_validation import to_toml

from flexgear.spec import load_variant

pytestmark = pytest.mark.slow  # four cold reductions: about a minute of CPU

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "spur_planetary"


def _mesh_force(spec) -> float:
    """F_n [N] of the module docstring (spur: cos beta_b = 1), r_b = m_n z_s cos(alpha_n) / 2."""
    g = spec.gears
    r_b = g.normal_module_mm * 1e-3 * g.sun_teeth * math.cos(math.radians(g.normal_pressure_angle_deg)) / 2
    t_sun = spec.load_case.load_torque_nm * g.sun_teeth / (g.sun_teeth + g.ring_teeth)
    return t_sun / (g.planet_count * r_b)


def test_rigid_and_flexible_variants_meet_hand_theory(tmp_path, example_cache):
    from flexgear.cli import main
    from flexgear.results import load_result

    variants = [str(EXAMPLE / f"{name}.toml") for name in ("rigid", "flexible")]
    assert main(["matrix", *variants, "--out", str(tmp_path / "out")]) == 0
    spec = load_variant(EXAMPLE / "flexible.toml").gearbox
    g = spec.gears
    for name in ("rigid", "flexible"):
        s = load_result(tmp_path / "out" / name).signals
        late = s[s.time_s >= 0.05]
        assert late.transmission_ratio.mean() == pytest.approx(g.sun_teeth / (g.sun_teeth + g.ring_teeth),
                                                               rel=1e-3), name
        forces = late[[f"{mesh}_mesh_force_{i}_n" for mesh in ("outer", "inner")
                       for i in range(1, g.planet_count + 1)]].mean()
        np.testing.assert_allclose(forces, _mesh_force(spec), rtol=0.01, err_msg=name)


def _without_friction(tmp_path: Path, formulation: str = "production", flexible: tuple[str, ...] | None = None
                      ) -> Path:
    """A copy of the example with frictionless teeth in ``formulation`` (the reduced bodies' keys depend on
    neither): its flexible variant, or the components ``flexible`` flexible and the others rigid."""
    data = tomllib.loads((EXAMPLE / "gearbox.toml").read_text())
    data["contact"] = {"friction_coefficient": 0.0}
    data["solver_assumed"] = {"formulation": formulation}
    folder = tmp_path / formulation
    folder.mkdir()
    (folder / "gearbox.toml").write_text(to_toml(data))
    variant = (EXAMPLE / "flexible.toml").read_text()
    if flexible is not None:
        names = ("input_shaft", "sun", "planets", "ring", "output_shaft", "carrier")
        variant = 'name = "flexible"\ngearbox = "gearbox.toml"\nmesh_level = "coarse"\n[components]\n' + "".join(
            f'{c} = "{"flexible" if c in flexible else "rigid"}"\n' for c in names)
    (folder / "flexible.toml").write_text(variant)
    return folder / "flexible.toml"


def _bearing_sensors(mbs, model, planets: int) -> list[tuple[int, int]]:
    """Per planet: sensors of the coordinates of its bearing's two nodes, the planet's side (its frame, or a flexible
    planet's seat node) and its pin's (flexgear.mbs.carrier.CarrierPins), the bearing acting between them."""
    import exudyn as exu
    from exudyn.itemInterface import SensorNode

    coordinates, out = exu.OutputVariableType.Coordinates, []
    for i in range(planets):
        name = f"planet{i + 1}"
        side = model.carrier_seat_nodes.get(name, model.bodies[name].node)
        out.append(tuple(mbs.AddSensor(SensorNode(nodeNumber=node, outputVariableType=coordinates, storeInternal=True))
                         for node in (side, model.carrier_pin_nodes[f"pin_{i}"])))
    return out


def _bearing_loads(mbs, sensors: tuple[int, int], bearing) -> np.ndarray:
    """(time, force x, y, z [N], moment x, y [N m]) in ground axes on the pin from the planet: the Table 2
    ``bearing``'s stiffness times the deflection (its damping's part averages out over a settled window)."""
    side, pin = (np.asarray(mbs.GetSensorStoredData(s)) for s in sensors)
    k = np.array([bearing.radial_stiffness_n_per_m] * 2 + [bearing.axial_stiffness_n_per_m]
                 + [bearing.tilt_stiffness_nm_per_rad] * 2)
    return np.column_stack([side[:, 0], k * (side[:, 1:6] - pin[:, 1:6])])


def test_flexible_planets_and_ring_carry_their_loads_on_the_turning_carrier(tmp_path, example_cache):
    import exudyn as exu
    from exudyn.itemInterface import SensorObject

    from flexgear.design import design
    from flexgear.mbs.assemble import build_gearbox
    from flexgear.mbs.recording import joint_axis_torque, simulation_settings

    variant = load_variant(_without_friction(tmp_path))
    d = design(variant.gearbox)
    spec, th, lc = d.spec, d.theory, d.spec.load_case
    g = spec.gears
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    model = build_gearbox(mbs, variant, design=d)
    assert all(model.bodies[n].flexible for n in ("sun", "ring", "planet1", "input_shaft", "output_shaft", "carrier"))
    ovt = exu.OutputVariableType
    bearings = _bearing_sensors(mbs, model, g.planet_count)
    joints = {f"joint_{gear}_0": mbs.AddSensor(SensorObject(objectNumber=model.joints[gear][0][0],
                                                            outputVariableType=ovt.Force, storeInternal=True))
              for gear in ("sun", "ring", "output_shaft")}
    mbs.Assemble()
    t_end = lc.end_time_s
    mbs.SolveDynamic(simulation_settings(variant, t_end, False), solverType=exu.DynamicSolverType.GeneralizedAlpha)
    window = 0.5 * (lc.ramp_time_s + t_end)
    omega_c = th.output_speed
    a_w = d.gears.centre_distance
    mass = model.bodies["planet1"].reduced.props.mass  # the flexible planet's own mass (its mesh)
    for i, sensors in enumerate(bearings):
        data = _bearing_loads(mbs, sensors, spec.bearings.planet)
        late = data[data[:, 0] >= window]
        pin = np.asarray(mbs.GetSensorStoredData(sensors[1]))[data[:, 0] >= window, 1:3] + np.asarray(
            mbs.GetNode(model.carrier_pin_nodes[f"pin_{i}"])["referenceCoordinates"][:2])
        psi = np.arctan2(pin[:, 1], pin[:, 0])  # the pin's angle as it is: the carrier lags the nominal one
        radial = np.mean(late[:, 1] * np.cos(psi) + late[:, 2] * np.sin(psi))
        tangential = np.mean(-late[:, 1] * np.sin(psi) + late[:, 2] * np.cos(psi))
        assert tangential == pytest.approx(lc.load_torque_nm / (g.planet_count * a_w), rel=2e-3), i
        assert radial == pytest.approx(mass * omega_c ** 2 * a_w, rel=5e-3), i
    share = g.sun_teeth / (g.sun_teeth + g.ring_teeth)
    for gear, torque in (("sun", share * lc.load_torque_nm), ("ring", (1 - share) * lc.load_torque_nm),
                         ("output_shaft", lc.load_torque_nm)):
        t, moment = joint_axis_torque(mbs, model, joints, gear)
        assert abs(moment[t >= window].mean()) == pytest.approx(torque, rel=1e-3), gear
    sc.Reset()


def test_the_production_formulation_on_the_turning_carrier_against_the_reference(tmp_path, example_cache):
    """The flexible variant, frictionless, in the production formulation (linear frames and modal equations, linear
    seats and joints, flexgear.mbs.spin and flexgear.mbs.joints) against the reference formulation (Exudyn's
    ``ObjectFFRFreducedOrder`` with its full floating-frame terms, generic joints, the bores' point springs on the
    carrier's pins) over the settled half of the run: every mean mesh force and load deflection within 1e-4, the
    mesh forces' 1x and 2x mesh-frequency amplitudes within 1 % (measured: 4.9e-6 and 1.9e-5; 0.03 %)."""
    from flexgear.cli import main
    from flexgear.results import load_result
    from flexgear.study.compare import harmonic_amplitudes

    runs = {}
    for formulation in ("production", "reference"):
        out = tmp_path / f"out_{formulation}"
        assert main(["run", str(_without_friction(tmp_path, formulation)), "--out", str(out)]) == 0
        runs[formulation] = load_result(out / "flexible")
    prod, ref = runs["production"].signals, runs["reference"].signals
    f_mesh = runs["production"].meta["theory"]["mesh_frequency_hz"]
    t = prod.time_s.to_numpy()
    dt = float(t[-1] - t[-2])
    n = int(np.floor(0.5 * (t[-1] - 0.02) * f_mesh) / f_mesh / dt)  # whole mesh cycles of the settled half
    forces = [c for c in prod.columns if "_mesh_force_" in c]
    deflections = [c for c in prod.columns if "_deflection_load_" in c]
    assert len(forces) == 6 and len(deflections) == 6
    for c in forces + deflections:
        a, b = prod[c].to_numpy()[-n:], ref[c].to_numpy()[-n:]
        assert a.mean() == pytest.approx(b.mean(), rel=1e-4), c
    for c in forces:
        a, b = (harmonic_amplitudes(s[c].to_numpy()[-n:], dt, f_mesh, (1, 2)) for s in (prod, ref))
        np.testing.assert_allclose(a, b, rtol=0.01, err_msg=c)


def test_the_flexible_carriers_pins_deflect_as_its_statics_under_the_planets_bearing_loads(tmp_path, example_cache):
    """The carrier alone flexible, frictionless: over the settled half of the run, each pin's mean deflection from
    the output shaft's rigid motion there, along the pin circle's tangent and in the carrier's axes, against the
    reduced carrier's static compliance with its seat held (the pins' 18 x 18 compliance that tests/test_carrier.py
    checks against the full FE model) times the run's mean bearing loads on the pins (force and tilt moments):
    within 1 % (measured 8e-5). The radial deflection also carries the carrier's own centrifugal load, which
    that compliance does not: not compared."""
    import exudyn as exu
    import scipy.linalg as la
    from exudyn.itemInterface import SensorNode
    from exudyn.rigidBodyUtilities import RotXYZ2RotationMatrix

    from flexgear.design import design
    from flexgear.fe.carrier import SEAT, pin_interface
    from flexgear.fe.joined import body_matrices, joint_rows
    from flexgear.mbs.assemble import build_gearbox
    from flexgear.mbs.recording import simulation_settings

    variant = load_variant(_without_friction(tmp_path, flexible=("carrier",)))
    d = design(variant.gearbox)
    lc, n_planets = d.spec.load_case, d.spec.gears.planet_count
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    model = build_gearbox(mbs, variant, design=d)
    carrier, shaft = model.bodies["carrier"], model.bodies[model.output_body]
    assert carrier.flexible and not shaft.flexible
    ovt = exu.OutputVariableType
    pins = [pin_interface(k) for k in range(n_planets)]

    def sensor(**kw) -> int:
        return mbs.AddSensor(kw.pop("kind")(**kw, storeInternal=True))

    pin_sensors = [sensor(kind=SensorNode, nodeNumber=model.carrier_pin_nodes[p], outputVariableType=ovt.Coordinates)
                   for p in pins]
    bearings = _bearing_sensors(mbs, model, n_planets)
    frame = sensor(kind=SensorNode, nodeNumber=shaft.node, outputVariableType=ovt.Coordinates)
    mbs.Assemble()
    mbs.SolveDynamic(simulation_settings(variant, lc.end_time_s, False),
                     solverType=exu.DynamicSolverType.GeneralizedAlpha)
    stored = {s: np.asarray(mbs.GetSensorStoredData(s)) for s in [*pin_sensors, frame]}
    loads = [_bearing_loads(mbs, b, d.spec.bearings.planet) for b in bearings]
    sc.Reset()
    shaft_q = stored[frame]
    late = np.flatnonzero(shaft_q[:, 0] >= 0.5 * (lc.ramp_time_s + lc.end_time_s))
    turns = [RotXYZ2RotationMatrix(shaft_q[i, 4:7]) for i in late]  # the output shaft's, and the seat's, axes
    body = carrier.reduced
    force, tangents, measured = np.zeros(6 * n_planets), [], []
    for k, p in enumerate(pins):
        point = body.interface(p).point
        pin, f = stored[pin_sensors[k]], loads[k]
        force[6 * k:6 * k + 3] = np.mean([r.T @ f[i, 1:4] for r, i in zip(turns, late, strict=True)], axis=0)
        force[6 * k + 3:6 * k + 5] = np.mean([r[:2, :2].T @ f[i, 4:6] for r, i in zip(turns, late, strict=True)],
                                             axis=0)
        measured.append(np.mean([r.T @ (point + pin[i, 1:4] - shaft_q[i, 1:4] - r @ point)
                                 for r, i in zip(turns, late, strict=True)], axis=0))
        tangents.append(np.array([-point[1], point[0], 0.0]) / np.hypot(point[0], point[1]))
    _, stiffness = body_matrices(body)
    held = la.null_space(joint_rows(body, SEAT, body.interface(SEAT).point))
    rows = np.vstack([joint_rows(body, p, body.interface(p).point) for p in pins]) @ held
    predicted = (rows @ np.linalg.solve(held.T @ stiffness @ held, rows.T @ force)).reshape(n_planets, 6)
    for k in range(n_planets):
        expected = predicted[k, :3] @ tangents[k]
        assert expected > 1e-6  # the pins trail: micrometres under the example's load
        assert measured[k] @ tangents[k] == pytest.approx(expected, rel=0.01), k


def test_the_flexible_carriers_linear_model_turns_with_it_and_matches_the_reference(tmp_path, example_cache):
    """The carrier alone flexible, frictionless, linearised (flexgear.modal.linearize, its equations in the
    carrier's axes with the pins' nodes orbiting): at the operating speed its modes below 3 kHz do not depend on the
    carrier's angle (two instants, within 1e-6: the pins' ties turn with the carrier, measured 1e-9); at rest they
    equal the reference formulation's (Exudyn's ``ObjectFFRFreducedOrder``, its pins' point springs) within 0.1 %
    (measured 0.03 %)."""
    from flexgear.modal import linearize, modes

    def frequencies(formulation: str, rpm: float, t_star: float) -> np.ndarray:
        folder = tmp_path / f"{formulation}_{rpm:g}_{t_star:g}"
        folder.mkdir()
        variant = load_variant(_without_friction(folder, formulation, flexible=("carrier",)))
        return modes(linearize(variant, speed_rpm=rpm, t_star=t_star), 3000.0).frequencies_hz

    rpm = load_variant(EXAMPLE / "flexible.toml").gearbox.load_case.input_speed_rpm
    turning = [frequencies("production", rpm, t) for t in (0.02, 0.0213)]
    assert len(turning[0]) == len(turning[1]) >= 12
    np.testing.assert_allclose(turning[1], turning[0], rtol=1e-6)
    production, reference = (frequencies(f, 0.0, 0.02) for f in ("production", "reference"))
    assert len(production) == len(reference)
    np.testing.assert_allclose(production, reference, rtol=1e-3)


def test_the_flexible_stages_speed_sweep_by_the_spin_fit(example_cache):
    """`flexgear sweep-speed`'s default linearisation (the spin fit of two linearisations, the second at a lower
    speed, on the first one's coordinates) runs on the flexible stage, its carrier turning. Solved directly (no modal
    basis), the fit reproduces its node: at the highest speed every amplitude equals that of the variant linearised
    there on its own (``each``) within 1e-6 of the indicator's largest."""
    from flexgear.harmonic import harmonic_response

    variant = load_variant(EXAMPLE / "flexible.toml")
    rpm = variant.gearbox.load_case.input_speed_rpm
    assert len(harmonic_response(variant, [0.75 * rpm, rpm], 2).table) > 0  # the default: on the modal basis
    fit = harmonic_response(variant, [0.75 * rpm, rpm], 2, modal_cutoff_ratio=None).table
    own = harmonic_response(variant, [rpm], 2, linearization="each").table
    top = fit[fit.speed_rpm == rpm].merge(own, on=["harmonic", "indicator"], suffixes=("", "_own"))
    assert len(top) == len(own) > 0
    scale = top.groupby("indicator").amplitude_own.transform("max")
    assert (abs(top.amplitude - top.amplitude_own) <= 1e-6 * scale).all()


def harmonic_against_time_run(variant, columns: tuple[str, ...]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """{column: (the harmonic response's 1x and 2x amplitudes, the settled time run's)} of ``variant`` at its load
    case's speed: flexgear.harmonic.harmonic_response linearised as the time model is built, three harmonics
    (Hill's method: more than read), against the whole mesh cycles of the run's last 0.1 s."""
    from flexgear.harmonic import harmonic_response
    from flexgear.mbs.run import run_variant
    from flexgear.study.compare import harmonic_amplitudes
    from flexgear.theory import mesh_frequency_hz

    spec = variant.gearbox
    rpm = spec.load_case.input_speed_rpm
    response = harmonic_response(variant, [rpm], 3, linearization="each")
    signals = run_variant(variant).signals
    t = signals.time_s.to_numpy()
    dt, f_mesh = float(t[-1] - t[-2]), mesh_frequency_hz(spec, rpm)
    n = int(math.floor(0.1 * f_mesh) / f_mesh / dt)  # whole mesh cycles of the last 0.1 s
    return {c: (response.amplitudes(c).iloc[0].to_numpy()[:2],
                harmonic_amplitudes(signals[c].to_numpy()[-n:], dt, f_mesh, (1, 2))) for c in columns}


def test_the_flexible_carriers_harmonic_response_matches_its_time_run(tmp_path, example_cache):
    """The carrier alone flexible, frictionless, at the example's 3000 rpm with a 5 us step (the derived step's
    integration error would be larger than the check): the linearised model's harmonic response
    (flexgear.harmonic.harmonic_response, in the carrier's axes, linearised as the time model is built) against the
    settled time run, planet 1's sun-planet and planet-ring mesh forces at 1x and 2x the mesh frequency within 2 %
    (measured 0.05 % and 0.3 %)."""
    import dataclasses

    variant = load_variant(_without_friction(tmp_path, flexible=("carrier",)))
    spec = variant.gearbox.with_fields("load_case", step_size_s=5e-6, end_time_s=0.3)
    found = harmonic_against_time_run(dataclasses.replace(variant, gearbox=spec),
                                      ("outer_mesh_force_1_n", "inner_mesh_force_1_n"))
    for column, (response, timed) in found.items():
        np.testing.assert_allclose(response, timed, rtol=0.02, err_msg=column)


def test_every_component_flexible_the_modes_turning_with_the_carrier_ring_in_its_time_run(example_cache):
    """Every component flexible, the carrier too: a force pulse on the output shaft at the operating point, the free
    response read in the carrier's axes (flexgear.modal.impulse), identified as damped modes; its clear peaks lie at
    the linearised model's modes (in the carrier's axes, with its Coriolis terms) within 1 % in frequency and 20 % in
    damping ratio (tests/test_modal_impulse.py's rule: the carrier's first elastic mode, 414 Hz, among them; measured
    within 0.3 %). Step and settling as that module's planetary case."""
    import dataclasses

    from test_modal_impulse import (
        F_MAX,
        ORDER,
        PLANETARY_SETTLE_S,
        PLANETARY_STEP_S,
        RAMP_S,
        SAMPLE_S,
        WINDOW_S,
        assert_clear_peaks_at_linearised_modes,
    )

    from flexgear.modal import linearize, modes
    from flexgear.modal.impulse import damped_poles, impulse_response

    variant = load_variant(EXAMPLE / "flexible.toml")
    assert variant.components["carrier"] == "flexible"
    variant = dataclasses.replace(variant, gearbox=variant.gearbox.with_fields("load_case", ramp_time_s=RAMP_S))
    linear = modes(linearize(variant), F_MAX)
    response = impulse_response(variant, window_s=WINDOW_S, step_s=PLANETARY_STEP_S, settle_s=PLANETARY_SETTLE_S)
    assert_clear_peaks_at_linearised_modes(linear, damped_poles(response, ORDER, sample_s=SAMPLE_S, f_max_hz=F_MAX))


def test_every_component_flexible_against_the_assembly_with_the_full_fe_carrier(example_cache):
    """Every component flexible, at rest, every mode below the default band (flexgear.modal.full_fe_check): the
    carrier's reduced body replaced by its full FE model in the assembly (its seat held rigid as the reduction
    holds it, found from the body's own modes; its pins' RBE3 motions free), the other bodies reduced in both (each
    has fewer modes than attachment motions): every mode within 1 % and paired (tests/test_modal_full_fe.py's rule;
    measured 0.05 %, MAC 1.000). With the seat free to deform (RBE3) the same assembly gives modes up to 26 % lower:
    the seat's rigidity is the reduction's assumption, and the check holds the full model to it."""
    from test_modal_full_fe import _check

    from flexgear.fe.carrier import SEAT, carrier_body
    from flexgear.fe.patches import rigid_interfaces
    from flexgear.modal.full_fe_check import compare_full_fe

    variant = load_variant(EXAMPLE / "flexible.toml")
    assert [i.name for i in rigid_interfaces(carrier_body(variant.gearbox, variant.mesh_level))] == [SEAT]
    result = compare_full_fe(variant)
    _check(result, ["sun", "ring", "planet_1", "planet_2", "planet_3", "input_shaft", "output_shaft"])
    assert len(result.full) >= 20
