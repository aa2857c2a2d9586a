"""The harmonic response over a speed grid from two linearisations (flexgear.harmonic.reduced) against direct
linearisation, the dense solve and the Campbell diagram.

(1) Spin dependence (flexgear.harmonic.reduced eq. 1): linearised at the same gear angles and dynamic modes, the
    matrices of a variant with flexible spinning bodies (model 2: flexible planets) are M, D constant, G linear and
    K quadratic in the spin speed, the static deflections quadratic; the fit from two speeds reproduces a direct
    linearisation at a third speed to round-off (the equations' structure, not a tolerance on the physics).
(2) The modal solve (modes below 1.5x the excitation frequency, residual static part and its mass corrections)
    agrees with the dense solve of all coordinates: the truncated modes' response is exact to order
    (f / f_k)^6 < 9 % of itself, and their share is small: within 1 % of each indicator's largest amplitude over
    the speeds and harmonics (a harmonic the planets' phasing cancels holds only round-off of the others).
(3) Resonance: lightly damped (damping ratios about 1 %, the peak shifts by order zeta^2 = 1e-4 from the undamped
    crossing), each crossing of the Campbell diagram (flexgear.modal.campbell_diagram) of model 1 at 1x-3x mesh that
    carries a prominent peak of the mesh-force and bearing-acceleration curves has that peak within 1 % of its speed.
"""

import dataclasses
import math

import numpy as np
import pytest

from flexgear.harmonic import harmonic_response
from flexgear.harmonic.reduced import fit_spin
from flexgear.harmonic.response import linearize_same_angle

RPM = math.pi / 30.0


@pytest.fixture(scope="module")
def model2_iso():
    from conftest import VARIANTS

    from flexgear.spec import load_variant

    variant = load_variant(VARIANTS / "model2.toml")
    spec = variant.gearbox.with_fields("contact", law="iso6336", friction_coefficient=0.0)
    spec = spec.with_fields("contact_assumed", stiffness_variation="contact_lines")
    return dataclasses.replace(variant, gearbox=spec)


def _terms(lm):
    return {"mass": lm.mass, "damping": lm.damping, "gyroscopic": lm.gyroscopic, "stiffness": lm.stiffness,
            "delta": np.array(list(lm.static_deflections.values()))}


def test_spin_fit_reproduces_a_direct_linearisation(model2_iso):
    ref = 6000.0
    a, b, c = (linearize_same_angle(model2_iso, n, ref) for n in (ref, 3000.0, 4500.0))
    assert a.coordinates == b.coordinates == c.coordinates
    assert any(co.kind == "elastic" for co in a.coordinates)  # flexible planets: elastic spin terms present
    fit = fit_spin(ref * RPM, 3000.0 * RPM, _terms(a), _terms(b))
    w = 4500.0 * RPM
    scale = {name: np.abs(getattr(c, name)).max() for name in ("mass", "damping", "gyroscopic", "stiffness")}
    assert np.abs(fit.mass - c.mass).max() <= 1e-10 * scale["mass"]
    assert np.abs(fit.damping - c.damping).max() <= 1e-10 * scale["damping"]
    assert np.abs(fit.gyroscopic(w) - c.gyroscopic).max() <= 1e-8 * scale["gyroscopic"]
    assert np.abs(fit.stiffness(w) - c.stiffness).max() <= 1e-10 * scale["stiffness"]
    delta = _terms(c)["delta"]
    np.testing.assert_allclose(fit.static_deflections(w), delta, rtol=1e-8)
    # the spin terms are not vanishing: the fit is tested on something
    assert np.abs(fit.g1).max() * w > 1e-6 * scale["stiffness"] / (2 * math.pi * 1000.0)
    assert np.abs(fit.k2).max() * w**2 > 1e-12 * scale["stiffness"]


def test_modal_solve_matches_dense_solve(model2_iso):
    speeds = np.linspace(1000.0, 7000.0, 13)
    modal = harmonic_response(model2_iso, speeds, 4)
    dense = harmonic_response(model2_iso, speeds, 4, modal_cutoff_ratio=None)
    for name in modal.indicators:
        if name == "dynamic_factor":
            continue
        got, ref = modal.complex(name).to_numpy(), dense.complex(name).to_numpy()
        assert np.all(np.abs(got - ref) <= 0.01 * np.abs(ref).max()), name
    kv_m, kv_d = modal.dynamic_factor().to_numpy(), dense.dynamic_factor().to_numpy()
    np.testing.assert_allclose(kv_m - 1.0, kv_d - 1.0, rtol=0.01)


def _lightly_damped(variant, factor: float = 0.1):
    """The variant with the mesh damping ratio and the bearings' damping per stiffness scaled by ``factor``."""
    spec = variant.gearbox
    spec = spec.with_fields("contact_assumed", mesh_damping_ratio=factor * spec.contact_assumed.mesh_damping_ratio)
    b = spec.bearings
    spec = spec.with_fields("bearings", **{
        f.name: dataclasses.replace(getattr(b, f.name), damping_per_stiffness_s=factor * getattr(
            b, f.name).damping_per_stiffness_s) for f in dataclasses.fields(b)})
    return dataclasses.replace(variant, gearbox=spec)


PROMINENCE = 2.0
"""A peak counts if it stands this many times above the higher of the lowest values on either side of it."""
SIGNIFICANCE = 0.05
"""... and holds at least this share of its curve's largest value: the stiffness variation's coupling of the
harmonics adds humps of a few percent of a curve (model 1, lightly damped: 3.5 % at 1839 rpm on the input bearing's
2x, 3-3.5 % between 1575 and 1648 rpm on its 3x), not resonances of a mode."""


def test_peaks_lie_at_campbell_crossings(model1, iso_spec):
    """Each crossing that carries a peak (a prominent peak of some curve has it as its nearest crossing of the same
    order) has one within 1 % of its speed (a curve may also show interference humps between two close modes: those
    are attributed to a crossing but are not its peak). The stiffness variation couples the harmonics
    (flexgear.harmonic.base, Hill's method), so a harmonic's curve also peaks where another harmonic meets a mode:
    a crossing whose peaks all lie within 1 % of a crossing of another order is carried by that one."""
    from flexgear.modal import campbell

    variant = _lightly_damped(dataclasses.replace(model1, gearbox=iso_spec))
    orders = (1, 2, 3)
    diagram = campbell(variant, np.linspace(1000.0, 7000.0, 13), orders=orders)
    speeds = 1000.0 * 1.0025 ** np.arange(int(math.log(7.0) / math.log(1.0025)) + 1)  # 0.25 % steps
    response = harmonic_response(variant, speeds, 3)
    attributed: dict[tuple[int, float], list[float]] = {}
    for name in ("outer_mesh_force_1_n", "inner_mesh_force_1_n", "input_bearing_accel_x_m_per_s2",
                 "output_bearing_accel_x_m_per_s2"):
        amp = response.amplitudes(name)
        for h in orders:
            y = amp[h].to_numpy()
            crossings = diagram.crossings[diagram.crossings.order == h].speed_rpm.to_numpy()
            for i in np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:])) + 1:
                if y[i] < PROMINENCE * max(y[:i].min(), y[i:].min()) or y[i] < SIGNIFICANCE * y.max():
                    continue
                nearest = float(crossings[np.argmin(np.abs(crossings - speeds[i]))])
                attributed.setdefault((h, nearest), []).append(float(speeds[i]))
    assert len(attributed) >= 10
    table = diagram.crossings
    for (h, crossing), peaks in attributed.items():
        closest = min(peaks, key=lambda n: abs(n - crossing))
        others = table[table.order != h].speed_rpm.to_numpy()
        coupled = all(np.min(np.abs(others / n - 1.0)) <= 0.01 for n in peaks)
        assert abs(closest / crossing - 1.0) <= 0.01 or coupled, (h, crossing, peaks)


@pytest.fixture(scope="module")
def iso_spec(gearbox):
    spec = gearbox.with_fields("contact", law="iso6336", friction_coefficient=0.0)
    return spec.with_fields("contact_assumed", stiffness_variation="contact_lines")
