"""The per-step mesh updates of a gear train in one compiled call: stiffness factors and tooth friction.

:class:`flexgear.mbs.contacts.StiffnessSchedule` (eq. 11-12: s(phi(t)) into the laws' symbolic
variables) and :class:`flexgear.mbs.contacts.MeshFriction` (friction from the state at the start of
the step as a generalized load) each need the drive angle, the mesh phases and the stiffness series
once per step. Run as two pre-step functions they cost four compiled calls and their Python glue;
:class:`MeshUpdates` does the same work in one (flexgear.laws.compiled.mesh_step), which is what a
run spends in Python per step besides Exudyn's own call overhead. It reads the state through views of
the system's coordinate vectors (no copies per step). The numbers are those of the two
parts (:meth:`MeshUpdates.reference` evaluates them with the parts' numpy reference implementations).
"""

from __future__ import annotations

import numpy as np

from flexgear.mbs.contacts import MeshFriction, StiffnessSchedule

__all__ = ["MeshUpdates"]


class MeshUpdates:
    """Pre-step user function: ``schedule``'s factors and ``friction``'s generalized load, one call per step."""

    compiled = True
    """False: runs evaluate the updates with :meth:`reference` (the numpy parts), for the tests."""

    def __init__(self, schedule: StiffnessSchedule, friction: MeshFriction):
        self.schedule, self.friction = schedule, friction
        f = friction
        # the kernel's rows per contact (flexgear.laws.compiled.mesh_step)
        self.law = np.ascontiguousarray([f.law.stiffness, f.law.exponent, f.law.damping_max, f.law.penetration_depth,
                                         f.mu, f.reg, f.phase_rate, f.offsets], dtype=float)
        # schedule variable k takes the factor of the first contact with its phase and stiffness series
        def key(rate: float, offset: float, mean: float, cos: np.ndarray, sin: np.ndarray) -> tuple:
            return (float(rate), float(offset), float(mean), *np.ravel(cos).tolist(), *np.ravel(sin).tolist())

        keys = [key(f.phase_rate[i], f.offsets[i], f._means[0, i], f._cos[0, i], f._sin[0, i])
                for i in range(len(f.mu))]
        means = np.broadcast_to(schedule._means, schedule.rate.shape)
        wanted = [key(schedule.rate[k], schedule.offsets[k], means[k], schedule._cos[k], schedule._sin[k])
                  for k in range(len(schedule.variables))]
        self.factor_rows = np.array([keys.index(k) for k in wanted], dtype=np.int64)
        self._q: np.ndarray | None = None  # views of the system's state (:meth:`bind`)
        self._bound_t = -np.inf

    def values_and_forces(self, t: float, q: np.ndarray, q_t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Stiffness factors of the schedule's variables and friction forces on the frames at the state ``q``,
        ``q_t`` (all ODE2 coordinates and rates; compiled, the arrays are overwritten by the next call)."""
        a = self._args
        self._kernel(t, *a[:2], q, q_t, *a[4:])
        return self._factors, self._frame_force

    def reference(self, t: float, q: np.ndarray, q_t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Same as :meth:`values_and_forces` with the two parts' numpy reference implementations."""
        f = self.friction
        forces = f.forces(t, *f.tooth_deflections(q, q_t, self._tooth), q_t[self._frames])
        self._frame_force[:] = forces
        self._factors[:] = self.schedule.values(t)
        return self._factors, self._frame_force

    def bind(self, mbs) -> None:
        """Coordinate indices, the kernel's arguments and the views of the system's state (after ``mbs.Assemble()``;
        done by the first call of a solve)."""
        from flexgear.laws.compiled import bound_entry, mesh_step, padded_sparse_rows

        f = self.friction
        n_c = len(f.mu)
        series = np.ascontiguousarray(np.concatenate([f._means[:, :, None], f._cos, f._sin], axis=2))
        # per contact: deflection coordinate, residual deflection coordinate (-1: none), the first contact with the
        # same phase, series, spin row and v_reg (the helix halves of a mesh), whose phase terms it shares
        index = np.empty((3, n_c), dtype=np.int64)
        index[:2] = f.tooth_index(mbs)
        keys = [(*self.law[[5, 6, 7], i], *series[:, i].ravel(), *f.spin_rows[i]) for i in range(n_c)]
        index[2] = [keys.index(k) for k in keys]
        self._tooth = index[:2]
        self._frames = f.frame_indices(mbs)
        n_force, n_k = len(mbs.GetObjectParameter(f.container, "forceVector")), self.factor_rows.size
        # the container's force vector, then the factors, then four work entries per contact
        self._out = np.zeros(n_force + n_k + 4 * n_c)
        self._force = self._out[:n_force]
        self._frame_force = self._out[:self._frames.size]
        self._factors = self._out[n_force:n_force + n_k]
        columns, sliding, spin = padded_sparse_rows(f.sliding_rows, f.spin_rows)
        self._set = [var.SetValue for var in self.schedule.variables]
        # views of the system's coordinates and rates, not copies: the solver updates these vectors in place
        # (their size is fixed once assembled), so each step reads the state without a copy
        self._q = mbs.systemData.GetODE2Coordinates(copy=False)
        self._q_t = mbs.systemData.GetODE2Coordinates_t(copy=False)
        # the kernel's arguments after t (q, q_t: the views; values_and_forces swaps in its own)
        self._args = (f.ramp_time, f.drive_speed, self._q, self._q_t, index, self._frames, self.law, series, columns,
                      np.ascontiguousarray([sliding, spin]), self.factor_rows, self._out, f.law.kind == "iso6336")
        self._kernel = mesh_step  # any arrays (values_and_forces); the bound ones per step:
        self._step = (bound_entry(mesh_step, (0.0, *self._args)) if self.compiled
                      else lambda t, *_: self.reference(t, self._q, self._q_t))
        self._bound_t = -np.inf

    def __call__(self, mbs, t: float) -> bool:
        if t < self._bound_t or self._q is None:  # a new solve (time went back): bind to its state afresh
            self.bind(mbs)
        self._bound_t = t
        self._step(t, *self._args)
        for set_value, value in zip(self._set, self._factors.tolist(), strict=True):
            set_value(value)
        mbs.SetObjectParameter(self.friction.container, "forceVector", self._force)
        return True
