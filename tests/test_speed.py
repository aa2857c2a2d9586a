"""The speed levers change no result: compiled per-step updates against the numpy reference
formulation, the lumped right-hand side for other integrators against the project's own RK4.

No timings here (benchmarks/bench_speed.py and benchmarks/bench_lumped.py measure them).
"""

import dataclasses

import numpy as np
import pytest
from conftest import VARIANTS
from standins import annulus_source, standin_frames

from flexgear.lumped.run import build_lumped_model, lumped_rhs, run_lumped
from flexgear.mbs.contact_kinematics import ContactKinematics, ModalColumn
from flexgear.mbs.contacts import MeshFriction, StiffnessSchedule
from flexgear.mbs.mesh_updates import MeshUpdates
from flexgear.mbs.run import run_variant
from flexgear.spec import load_variant
from flexgear.study.agreement import signal_agreement


class _Blocks:
    """Stand-in for flexgear.mbs.mesh_constraint.MeshConstraint (two gear pairs, rows 0 and 1) and an Exudyn system."""

    def __init__(self):
        self.blocks = [(7, np.array([0]), np.ix_([0], np.arange(0, 24))),
                       (9, np.array([1]), np.ix_([1], np.r_[0:6, 12:30]))]
        self.written = {}

    def blocks_with_rows(self, rows):
        return [i for i, (_, r, _) in enumerate(self.blocks) if np.isin(r, rows).any()]

    def SetObjectParameter(self, obj, name, value):  # noqa: N802 - Exudyn's name
        self.written[obj] = np.array(value)


def test_compiled_modal_columns_match_the_numpy_reference():
    rng = np.random.default_rng(3)
    columns = [ModalColumn(row, body, sign, psi, spin, rng.normal(size=(720, m)))
               for row, body, sign, psi, spin, m in ((0, "sun", 1.0, 0.3, 1.0, 5), (1, "ring", -1.0, 2.1, -0.3, 7),
                                                     (1, "sun", 1.0, -1.2, 1.0, 5))]
    system = _Blocks()
    kin = ContactKinematics(system, rng.normal(size=(2, 30)), columns, {"sun": 12, "ring": 18}, 0.5, 628.3)
    for t in (0.0, 1e-5, 0.1234, 0.49999, 0.5, 0.61):
        ref = kin.reference_matrix_at(t)
        # same formula; the drive angle (~160 rad) is summed in another order: round-off ~1e-14 rad x grid slope
        assert np.max(np.abs(kin.matrix_at(t) - ref)) < 1e-9 * np.max(np.abs(ref))
        kin(system, t)  # the pre-step writes each pair's block of the matrix
        for obj, _, sub in system.blocks:
            np.testing.assert_allclose(system.written[obj], ref[sub], rtol=0, atol=1e-9 * np.max(np.abs(ref)))


@pytest.fixture(scope="module")
def short_model7():
    """Model 6 (every gear flexible: sun, planets, ring; stand-in annulus bodies) on a shortened load case.

    Every flexible gear pair's contact columns are updated per step, as in model 7; the shafts stay rigid
    because the stand-in annuli have no bearing-seat interface (the supports act at the seats).
    """
    v = load_variant(VARIANTS / "model6.toml")
    g = v.gearbox
    g = g.with_changes(load_case=dataclasses.replace(g.load_case, ramp_time_s=0.006, end_time_s=0.012))
    return dataclasses.replace(v, gearbox=standin_frames(g))


def test_compiled_updates_keep_every_signal_of_the_reference_formulation(short_model7, monkeypatch):
    """The agreement rule: means within 0.1 %, 1x mesh amplitudes within 2 % (flexgear.study.agreement)."""
    fast = run_variant(short_model7, reduced_source=annulus_source)
    assert fast.ok, fast.meta.get("reason")
    monkeypatch.setattr(ContactKinematics, "matrix_at", ContactKinematics.reference_matrix_at)
    monkeypatch.setattr(StiffnessSchedule, "fast_values", StiffnessSchedule.values)
    monkeypatch.setattr(MeshFriction, "fast_forces", MeshFriction.forces)
    monkeypatch.setattr(MeshUpdates, "compiled", False)
    ref = run_variant(short_model7, reduced_source=annulus_source)
    assert ref.ok, ref.meta.get("reason")
    lc = short_model7.gearbox.load_case
    agreement = signal_agreement(ref, fast, (lc.ramp_time_s, lc.end_time_s), ref.meta["theory"]["mesh_frequency_hz"])
    assert agreement.ok(), agreement.table
    # the rule has teeth: the mesh forces carry a resolved 1x amplitude
    assert agreement.table.loc["outer_mesh_force_1_n", "ref_amp_1x"] > 1e-3 * agreement.table.loc[
        "outer_mesh_force_1_n", "ref_mean"]


@pytest.mark.parametrize("law", ["iso6336", "impact"])
def test_lumped_rhs_is_the_kernel_that_run_lumped_integrates(gearbox, law):
    """Classical RK4 in Python on lumped_rhs, with the configured substeps, reproduces run_lumped (under both
    contact laws: the linear one of eq. 10-13 and the study's impact law)."""
    gearbox = gearbox.with_fields("contact", law=law)
    h_out, n_out = gearbox.load_case.step_size_s, 40
    substeps = gearbox.lumped_assumed.integration_substeps
    own = run_lumped(gearbox, t_end_s=n_out * h_out).signals
    model = build_lumped_model(gearbox)
    f = lumped_rhs(model)
    y, h = np.zeros(2 * model.free.size), h_out / substeps
    rows = []
    for step in range(n_out + 1):
        rows.append(f.record(step * h_out, y))
        for sub in range(substeps):
            t = step * h_out + sub * h
            k1 = f(t, y)
            k2 = f(t + h / 2, y + h / 2 * k1)
            k3 = f(t + h / 2, y + h / 2 * k2)
            k4 = f(t + h, y + h * k3)
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    rec = np.array(rows)
    n = gearbox.gears.planet_count
    forces = own.filter(regex=r"mesh_force").to_numpy()
    # the teeth are in contact by the end of the span (ramps just begun; the impact law's force grows as delta^1.5)
    assert forces[-1].min() > (0.1 if law == "iso6336" else 0.0)
    np.testing.assert_allclose(rec[:, 3:3 + 2 * n], forces, rtol=1e-9, atol=1e-9 * np.abs(forces).max())
    np.testing.assert_allclose(rec[:, 1], own["output_speed_rad_per_s"], rtol=1e-9, atol=1e-9)


def test_plain_python_rhs_equals_the_compiled_one(gearbox):
    model = build_lumped_model(gearbox)
    rng = np.random.default_rng(7)
    y = np.r_[rng.normal(scale=1e-6, size=model.free.size), rng.normal(scale=1e-2, size=model.free.size)]
    compiled, plain = lumped_rhs(model), lumped_rhs(model, compiled=False)
    for t in (0.0, 0.2, 0.55):
        a, b = compiled(t, y), plain(t, y)
        assert np.max(np.abs(a - b)) <= 1e-10 * np.max(np.abs(a))


def test_fused_mesh_updates_equal_their_parts(model1):
    """One compiled call per step (MeshUpdates) gives the schedule's factors and the friction forces."""
    import exudyn as exu

    from flexgear.mbs.gearbox import build_star_gearbox

    mbs = exu.SystemContainer().AddSystem()
    model = build_star_gearbox(mbs, model1)
    mbs.Assemble()
    pre_step = mbs.GetPreStepUserFunction()["function"]
    fused = [f for f in getattr(pre_step, "functions", [pre_step]) if isinstance(f, MeshUpdates)]
    assert len(fused) == 1
    updates = fused[0]
    updates.bind(mbs)
    rng = np.random.default_rng(11)
    n = mbs.systemData.ODE2Size()
    aux = updates._tooth[0]
    for t in (0.01, 0.3, 0.55):
        q, q_t = rng.normal(0, 1e-3, n), rng.normal(0, 300, n)
        q[aux] = rng.uniform(-1e-4, 5e-4, aux.size)
        q_t[aux] = rng.normal(0, 1e-3, aux.size)
        factors, forces = (x.copy() for x in updates.values_and_forces(t, q, q_t))
        ref_factors, ref_forces = (x.copy() for x in updates.reference(t, q, q_t))
        assert len(factors) == len(model.contacts) // 2  # helix halves share their factor
        assert np.max(np.abs(factors - ref_factors)) < 1e-12
        assert np.max(np.abs(forces - ref_forces)) < 1e-9 * np.max(np.abs(ref_forces))


def test_matrix_orders_runs_by_flexible_bodies():
    """The matrix starts the runs with the most flexible bodies first (Table 3: model 7 has all nine)."""
    from flexgear.study.matrix import _flexible_bodies

    counts = {p.stem: _flexible_bodies(load_variant(p)) for p in sorted(VARIANTS.glob("model*.toml"))}
    assert counts["model1"] == 0 and counts["model7"] == 9  # 2 shafts, sun, ring, 5 planets
    assert counts["model2"] == 5 and counts["model3"] == 2


def test_matrix_orders_runs_by_their_dynamic_modes(monkeypatch, tmp_path):
    """With the bodies cached, the matrix orders the runs by the sum over their flexible bodies of (dynamic modes)^2,
    each count by the rule the build applies: a gear its modes below the cut-off, shafts and the bolted ring every
    mode (checked against the whole reduced bodies loaded); with a body missing, by the flexible bodies' count."""
    from flexgear.fe.reduced import component_reduced_body
    from flexgear.mbs.gearbox import dynamic_modes, run_cost
    from flexgear.study.matrix import _run_order
    from flexgear.theory import theory

    variants = {p.stem: load_variant(p) for p in sorted(VARIANTS.glob("model*.toml"))}
    spec = variants["model7"].gearbox
    cutoff = spec.reduction_assumed.dynamic_cutoff_mesh_orders * theory(spec).mesh_frequency
    counts = {}
    for component in ("input_shaft", "sun", "planets", "ring", "output_shaft"):
        body = component_reduced_body(spec, component, variants["model7"].mesh_level)
        geometry = "planet" if component == "planets" else component
        counts[component] = dynamic_modes(geometry, body.frequencies_hz, cutoff)
        if component in ("input_shaft", "output_shaft") or component == "ring":
            assert counts[component] == body.n_modes
        elif component in ("sun", "planets"):
            assert 1 <= counts[component] == body.modes_below(cutoff) < body.n_modes
    planets = spec.gears.planet_count
    expected = sum(n * n * (planets if c == "planets" else 1) for c, n in counts.items())
    assert run_cost(variants["model7"]) == pytest.approx(expected, rel=1e-12)
    assert run_cost(variants["model1"]) == 0.0
    order = _run_order(variants)
    assert order[0] == "model7" and order[-1] == "model1"
    monkeypatch.setenv("FLEXGEAR_CACHE_DIR", str(tmp_path))  # nothing cached: the count of flexible bodies
    assert run_cost(variants["model7"]) is None
    assert _run_order(variants)[:1] == ["model7"] and _run_order(variants)[-1] == "model1"


def test_mesh_updates_read_views_that_follow_the_solver(model1, monkeypatch):
    """The per-step mesh updates read the state through views of the system's vectors (no copies): a run gives
    bit-identical signals to one that hands them fresh copies every step, and the views are still the
    system's state at the end of the run."""
    short = dataclasses.replace(model1, gearbox=model1.gearbox.with_changes(load_case=dataclasses.replace(
        model1.gearbox.load_case, ramp_time_s=0.004, end_time_s=0.008)))
    seen = []
    original = MeshUpdates.__call__

    def checked(self, mbs, t):
        ok = original(self, mbs, t)
        seen.append(np.array_equal(self._q, mbs.systemData.GetODE2Coordinates())
                    and np.array_equal(self._q_t, mbs.systemData.GetODE2Coordinates_t()))
        return ok

    monkeypatch.setattr(MeshUpdates, "__call__", checked)
    fast = run_variant(short)
    assert fast.ok, fast.meta.get("reason")
    assert len(seen) >= 800 and all(seen)

    def copying(self, mbs, t):
        if self._q is None:
            self.bind(mbs)
        self._q, self._q_t = mbs.systemData.GetODE2Coordinates(), mbs.systemData.GetODE2Coordinates_t()
        return original(self, mbs, t)

    monkeypatch.setattr(MeshUpdates, "__call__", copying)
    ref = run_variant(short)
    assert ref.ok, ref.meta.get("reason")
    forces = fast.signals.filter(regex="mesh_force").to_numpy()
    assert forces[-1].min() > 10.0  # the teeth carry load, with friction and varying stiffness acting
    np.testing.assert_array_equal(fast.signals.to_numpy(), ref.signals.to_numpy())


def test_pre_step_chain_drops_a_finished_function():
    from flexgear.mbs.contact_kinematics import PreStepChain

    calls = []

    class Ramp:
        finished = False

        def __call__(self, mbs, t):
            calls.append(("ramp", t))
            self.finished = t >= 2
            return True

    chain = PreStepChain([Ramp(), lambda mbs, t: calls.append(("mesh", t)) or True])
    for t in range(5):
        assert chain(None, t)
    assert [t for name, t in calls if name == "ramp"] == [0, 1, 2]
    assert [t for name, t in calls if name == "mesh"] == [0, 1, 2, 3, 4]
