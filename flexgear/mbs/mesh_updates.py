"""The per-step mesh updates of a gear train in one compiled call: stiffness factors and tooth friction.

:class:`flexgear.mbs.contacts.StiffnessSchedule` (eq. 11-12: s(phi(t)) into the laws' symbolic
variables) and :class:`flexgear.mbs.contacts.MeshFriction` (friction from the state at the start of
the step as a generalized load) each need the drive angle, the mesh phases and the stiffness series
once per step. Run as two pre-step functions they cost four compiled calls and their Python glue;
:class:`MeshUpdates` does the same work in one (flexgear.laws.compiled.mesh_step), which is what a
run spends in Python per step besides Exudyn's own call overhead. The numbers are those of the two
parts (:meth:`MeshUpdates.reference` evaluates them with the parts' numpy reference implementations).
"""

from __future__ import annotations

import numpy as np

from flexgear.mbs.contacts import MeshFriction, StiffnessSchedule

__all__ = ["MeshUpdates"]


class MeshUpdates:
    """Pre-step user function: ``schedule``'s factors and ``friction``'s generalized load, one call per step."""

    def __init__(self, schedule: StiffnessSchedule, friction: MeshFriction):
        self.schedule, self.friction = schedule, friction
        f = friction
        self.law = np.ascontiguousarray([f.law.stiffness, f.law.exponent, f.law.damping_max,
                                         f.law.penetration_depth, f.mu, f.reg], dtype=float)
        # schedule variable k takes the factor of the first contact with its phase and stiffness series
        def key(rate: float, offset: float, mean: float, cos: np.ndarray, sin: np.ndarray) -> tuple:
            return (float(rate), float(offset), float(mean), *np.ravel(cos).tolist(), *np.ravel(sin).tolist())

        keys = [key(f.phase_rate[i], f.offsets[i], f._means[0, i], f._cos[0, i], f._sin[0, i])
                for i in range(len(f.mu))]
        means = np.broadcast_to(schedule._means, schedule.rate.shape)
        wanted = [key(schedule.rate[k], schedule.offsets[k], means[k], schedule._cos[k], schedule._sin[k])
                  for k in range(len(schedule.variables))]
        self.factor_rows = np.array([keys.index(k) for k in wanted], dtype=np.int64)
        self._index: tuple[np.ndarray, np.ndarray] | None = None
        self._force: np.ndarray | None = None

    def values_and_forces(self, t: float, q: np.ndarray, q_t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Stiffness factors of the schedule's variables and friction forces on the frames (compiled; the
        arrays are overwritten by the next call)."""
        head, tail = self._args
        self._kernel(float(t), *head, q, q_t, *tail)
        return self._factors, self._force[:self._index[1].size]

    def reference(self, t: float, q: np.ndarray, q_t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Same as :meth:`values_and_forces` with the two parts' numpy reference implementations."""
        aux, frames = self._index
        forces = self.friction.forces(t, q[aux], q_t[aux], q_t[frames])
        self._force[:frames.size] = forces
        return self.schedule.values(t), forces

    def bind(self, mbs) -> None:
        """Coordinate indices and the force buffer (after ``mbs.Assemble()``; done by the first call)."""
        f = self.friction
        self._index = (f.deflection_indices(mbs),
                       np.concatenate([np.arange(mbs.GetNodeODE2Index(b.node), mbs.GetNodeODE2Index(b.node) + 6)
                                       for b in f.bodies]).astype(np.int64))
        self._force = np.zeros(len(mbs.GetObjectParameter(f.container, "forceVector")))
        self._factors = np.zeros(self.factor_rows.size)
        from flexgear.laws.compiled import mesh_step, padded_sparse_rows

        columns, sliding, spin = padded_sparse_rows(f.sliding_rows, f.spin_rows)

        # the kernel and its arguments, looked up once (this runs every step)
        self._kernel = mesh_step
        self._args = ((f.ramp_time, f.drive_speed, f.phase_rate, f.offsets),
                      (*self._index, self.law, f._means, f._cos, f._sin, columns, sliding, spin,
                       self.factor_rows, self._force, self._factors, np.zeros(len(f.mu)), f.law.kind == "iso6336"))
        self._set = [var.SetValue for var in self.schedule.variables]

    def __call__(self, mbs, t: float) -> bool:
        if self._index is None:
            self.bind(mbs)
        head, tail = self._args
        self._kernel(t, *head, *self.friction.tooth_state(mbs), *tail)
        for set_value, value in zip(self._set, self._factors.tolist(), strict=True):
            set_value(value)
        mbs.SetObjectParameter(self.friction.container, "forceVector", self._force)
        return True

