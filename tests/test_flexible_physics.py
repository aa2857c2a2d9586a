"""Flexible bodies under the gear loads, law = "iso6336", converged coarse bodies.

- model 4 (flexible sun and ring) changes the inner mesh-force ripple against model 1 by more than 10 % and by
  more than ten times what halving the step changes (measured on model 1 here: model 4 at h/2 costs minutes;
  the halved step is measured outside the tests);
- the load-induced deflection of each flexible gear at its meshes (flexgear.mbs.deflection, relative to its
  seat), averaged over its meshes, equals static_compliance (flexgear.fe.compliance, the same seat held, the
  contact kernel's loads) times the mesh forces within 10 %; mesh by mesh too for the sun. The ring's
  mesh-by-mesh static prediction is ill-conditioned: a single planet load bends it about 20 times more
  than the five together (n = 2, 3 against n = 0, 5), so a snapshot's per-mesh values swing with the
  mesh's small asymmetries (+-20 % measured) while the travelling loads average them in the run.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import VARIANTS

from flexgear.laws.ramps import drive_angle
from flexgear.mbs.run import run_variant
from flexgear.spec import load_variant
from flexgear.study.compare import harmonic_amplitudes
from flexgear.theory import theory

T_END, WINDOW = 0.06, 0.03


def _run(name: str, step: float = 1e-5):
    return _run_spec(load_variant(VARIANTS / f"{name}.toml"), step)


def _run_spec(v, step: float = 1e-5):
    gb = v.gearbox
    gb = gb.with_changes(contact=dataclasses.replace(gb.contact, law="iso6336"),
                         load_case=dataclasses.replace(gb.load_case, ramp_time_s=0.02, end_time_s=T_END,
                                                       step_size_s=step))
    r = run_variant(dataclasses.replace(v, gearbox=gb))
    assert r.ok, r.meta.get("reason")
    return gb, r


def _ripple(gb, result, kind: str = "inner") -> float:
    """Mesh-force ripple [N]: rss of the 1x-3x mesh-frequency amplitudes, mean over the planets."""
    s = result.signals
    w = s[s.time_s >= WINDOW]
    f_mesh = theory(gb).mesh_frequency
    amps = [np.sqrt(np.sum(harmonic_amplitudes(w[f"{kind}_mesh_force_{i}_n"].to_numpy(), gb.load_case.step_size_s,
                                               f_mesh, (1, 2, 3)) ** 2)) for i in range(1, 6)]
    return float(np.mean(amps))


@pytest.fixture(scope="module")
def runs():
    """Model 1 at h and h/2, model 4 (converged coarse bodies) at h; law = "iso6336", ramps over 0.02 s, 0.06 s."""
    return {key: _run(*key) for key in (("model1", 1e-5), ("model1", 0.5e-5), ("model4", 1e-5))}


@pytest.mark.slow
def test_flexible_sun_and_ring_change_the_inner_ripple(runs):
    r = {key: _ripple(*val) for key, val in runs.items()}
    change = r["model4", 1e-5] - r["model1", 1e-5]
    step = abs(r["model1", 0.5e-5] - r["model1", 1e-5])
    assert abs(change) > 0.10 * r["model1", 1e-5], r
    assert abs(change) > 10.0 * step, r


def _measured_and_predicted(gb, result, gear: str, kind: str) -> tuple[np.ndarray, np.ndarray]:
    """Per mesh (5,), averaged over 13 times of the window: the load-induced deflection the run reports and
    static_compliance (the gear held as the multibody model holds it: the sun at its bore, the ring at its bolt
    patches; the contact kernel's loads) times the mesh
    forces split equally over the helix halves."""
    from flexgear.fe.compliance import static_compliance
    from flexgear.fe.reduced import component_load_circles, component_reduced_body
    from flexgear.mbs.deflection import held_interfaces
    from flexgear.mbs.gearbox import mesh_contacts

    s = result.signals
    rows = [int(np.argmin(np.abs(s.time_s.to_numpy() - t))) for t in np.linspace(WINDOW, T_END, 13)]
    lc = gb.load_case
    red = component_reduced_body(gb, gear, "coarse")
    circles = component_load_circles(gb, gear, gb.reduction_assumed.contact_fourier_order)
    mine = [c for c in mesh_contacts(gb) if c.name.startswith(kind)]
    predicted, measured = [], []
    for row in rows:
        t = float(s.time_s.iloc[row])
        spin = mine[0].spin_per_drive_angle[0 if gear == "sun" else 1]
        ang = spin * float(drive_angle(t, lc.ramp_time_s, lc.input_speed_rad_s))
        rot = np.array([[np.cos(ang), np.sin(ang), 0.0], [-np.sin(ang), np.cos(ang), 0.0], [0.0, 0.0, 1.0]])
        points = np.array([rot @ np.asarray(c.point) for c in mine])
        normals = np.array([rot @ np.asarray(c.normal) for c in mine])
        comp = static_compliance(red, points, normals, held_interfaces(red, gear), kernel=circles)
        forces = np.repeat([s[f"{kind}_mesh_force_{i}_n"].iloc[row] for i in range(1, 6)], 2) / 2.0
        predicted.append((comp @ forces).reshape(5, 2).mean(1))
        measured.append([s[f"{kind}_deflection_load_{i}_m"].iloc[row] for i in range(1, 6)])
    return np.mean(measured, 0), np.mean(predicted, 0)


@pytest.mark.slow
def test_load_deflection_equals_static_compliance_times_mesh_forces(runs):
    gb, result = runs["model4", 1e-5]
    for gear, kind in (("sun", "outer"), ("ring", "inner")):
        measured, predicted = _measured_and_predicted(gb, result, gear, kind)
        assert measured.mean() == pytest.approx(predicted.mean(), rel=0.10), (gear, measured, predicted)
        if gear == "sun":
            np.testing.assert_allclose(measured, predicted, rtol=0.10)


@pytest.mark.heavy
def test_bolt_patched_ring_deflects_by_its_static_compliance():
    """Model 4 with the ring on bolt patches (each patch held by the output shaft), Table 5's torque and 50 N m: the
    ring's load deflection equals static_compliance with every patch held times the mesh forces within 10 % at both
    (measured 1.002 at Table 5's torque), and grows with them by it within 5 % (measured 1.001). With the patches
    held at zero against the mean axes in the centrifugal split (before flexgear.mbs.deflection.centrifugal_response
    let them move together) it carried a load-free 0.28 um: 1.05 against 0.77 um. About 1 min (2 min cold)."""
    v = load_variant(VARIANTS / "model4.toml")
    pairs = []
    for torque in (None, 50.0):
        gb = v.gearbox
        if torque is not None:
            gb = gb.with_changes(load_case=dataclasses.replace(gb.load_case, load_torque_nm=torque))
        gb, result = _run_spec(dataclasses.replace(v, gearbox=gb))
        pairs.append(_measured_and_predicted(gb, result, "ring", "inner"))
    for measured, predicted in pairs:
        assert measured.mean() == pytest.approx(predicted.mean(), rel=0.10), pairs
    (m_full, p_full), (m_low, p_low) = pairs
    slope = (m_full.mean() - m_low.mean()) / (p_full.mean() - p_low.mean())
    assert slope == pytest.approx(1.0, rel=0.05), pairs
