"""The check of a flexible variant's linearised modes against the same assembly with full FE bodies.

At zero speed (no spin terms) three sets of undamped natural frequencies f = sqrt(s) / (2 pi) below ``f_max``:

- ``model``: the variant's linear model as it is (flexgear.modal.linear.linearize: reduced bodies, the gears'
  modes above the dynamic cut-off as residual compliance);
- ``all_modes``: the same with every mode of the bodies' bases kept (no residual compliance); the couplings of
  the reference are recovered from this linearisation (flexgear.modal.full_fe.recover), and its frequencies
  recomputed from the recovered couplings (``recovery``: their largest relative difference) check that step;
- ``full``: every flexible body replaced by its full FE model (flexgear.modal.full_fe), with the same bearings,
  joints and tangent mesh springs at the static deflection of the all-modes operating point.

Modes are paired in ascending order (both sets hold the same count below ``f_max``: the reduced bodies are
Ritz approximations, each frequency an upper bound of the full model's in the same order).
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

from flexgear.modal.full_fe import (
    assembled,
    attachments,
    body_fe_model,
    eigenvalues,
    full_flexibility,
    linear_system,
    recover,
    reduced_flexibility,
)
from flexgear.spec import Variant

__all__ = ["FullFEComparison", "compare_full_fe", "default_f_max_hz"]


@dataclass
class FullFEComparison:
    """Frequencies [Hz] (module docstring), each (n,) ascending; ``recovery`` and ``leak`` (relative) the checks of
    the couplings' recovery; ``deflection_change``: the largest relative difference of the contacts' static
    deflections between the model and the all-modes linearisation; ``seconds``: wall time per step."""

    variant: str
    f_max_hz: float
    model: np.ndarray
    all_modes: np.ndarray
    full: np.ndarray
    recovery: float
    leak: float
    deflection_change: float
    seconds: dict[str, float]

    @property
    def error(self) -> np.ndarray:
        """f_model / f_full - 1 per mode."""
        return self.model / self.full - 1.0

    @property
    def basis_error(self) -> np.ndarray:
        """f_all_modes / f_full - 1 per mode."""
        return self.all_modes / self.full - 1.0

    def table(self) -> str:
        lines = [f"{self.variant}: {len(self.full)} modes below {self.f_max_hz:.0f} Hz, zero speed",
                 f"{'mode':>4} {'model [Hz]':>12} {'all modes [Hz]':>15} {'full FE [Hz]':>13} {'model err %':>12} "
                 f"{'all-modes err %':>16}"]
        for i, (a, b, c) in enumerate(zip(self.model, self.all_modes, self.full, strict=True)):
            lines.append(f"{i + 1:4d} {a:12.3f} {b:15.3f} {c:13.3f} {100 * (a / c - 1):12.4f} "
                         f"{100 * (b / c - 1):16.4f}")
        lines.append(f"max |model err| {100 * np.abs(self.error).max():.4f} %, max |all-modes err| "
                     f"{100 * np.abs(self.basis_error).max():.4f} %, recovery {self.recovery:.1e}, "
                     f"leak {self.leak:.1e}, static deflection change {self.deflection_change:.1e}")
        return "\n".join(lines)


def default_f_max_hz(variant: Variant) -> float:
    """Three times the mesh frequency at the load case's input speed [Hz]."""
    from flexgear.theory import theory

    return 3.0 * theory(variant.gearbox).mesh_frequency


def _frequencies(model, s_max: float) -> np.ndarray:
    from scipy.linalg import eigh

    w2 = eigh(model.stiffness, model.mass, eigvals_only=True)
    return w2[(w2 > 0.0) & (w2 <= s_max)]


def compare_full_fe(variant: Variant, f_max_hz: float | None = None, progress=None) -> FullFEComparison:
    """:class:`FullFEComparison` of ``variant`` at zero speed below ``f_max_hz`` (default
    :func:`default_f_max_hz`). ``progress``: a callable taking a message, or None."""
    from flexgear.modal.linear import linearize

    say = progress or (lambda msg: None)
    f_max = default_f_max_hz(variant) if f_max_hz is None else float(f_max_hz)
    s_max = (2 * np.pi * f_max) ** 2
    seconds = {}
    t = time.perf_counter()
    model = linearize(variant, 0.0)
    all_variant = dataclasses.replace(variant, gearbox=variant.gearbox.with_fields(
        "reduction_assumed", dynamic_cutoff_mesh_orders=0.0))
    all_model = linearize(all_variant, 0.0)
    common = set(model.static_deflections) & set(all_model.static_deflections)
    change = max((abs(model.static_deflections[c] / all_model.static_deflections[c] - 1.0) for c in common),
                 default=0.0)
    seconds["linearise"] = time.perf_counter() - t
    t = time.perf_counter()
    system = linear_system(variant, 0.0)
    bodies = attachments(system)
    coupled = recover(system, bodies)
    s_all = _frequencies(all_model, 1.05 * s_max)
    s_rec = eigenvalues(*assembled(coupled, [reduced_flexibility(b) for b in bodies])[:2], s_max=1.05 * s_max)
    n = min(len(s_all), len(s_rec))
    recovery = float(np.abs(np.sqrt(s_rec[:n] / s_all[:n]) - 1.0).max()) if len(s_rec) == len(s_all) else np.inf
    seconds["recover"] = time.perf_counter() - t
    t = time.perf_counter()
    flex, cache, fe_cache = [], {}, {}
    for b in bodies:
        name = next(nm for nm, body in system.bodies.items() if body.flexible and _component(nm) == b.component)
        body = system.bodies[name]
        fe_key = "planet" if name.startswith("planet") else name
        key = (fe_key, b.weights.indices.tobytes(), np.round(b.weights.data, 12).tobytes())
        if key not in cache:
            if fe_key not in fe_cache:
                say(f"  {name}: full FE model")
                fe_cache = {fe_key: body_fe_model(system.spec, name, body.reduced, variant.mesh_level)}
            say(f"  {name}: full FE flexibility at {b.weights.shape[1]} attachment motions")
            cache[key] = full_flexibility(fe_cache[fe_key], b.weights, 1.05 * s_max, body.reduced.frequencies_hz)
        flex.append(cache[key])
    seconds["full FE bodies"] = time.perf_counter() - t
    t = time.perf_counter()
    t0, t1, rest = assembled(coupled, flex)
    s_full = eigenvalues(t0, t1, rest, s_max=1.05 * s_max)
    seconds["assembled eigenvalues"] = time.perf_counter() - t
    s_model = _frequencies(model, s_max)
    n = len(s_model)
    if len(s_full) < n or len(s_all) < n:
        raise RuntimeError(f"{variant.name}: {len(s_model)} model modes below {f_max:.0f} Hz but "
                           f"{len(s_full)} full FE and {len(s_all)} all-modes modes up to 5 % above")
    hz = [np.sqrt(s[:n]) / (2 * np.pi) for s in (s_model, s_all, s_full)]
    return FullFEComparison(variant.name, f_max, *hz, recovery, coupled.leak, change, seconds)


def _component(body: str) -> str:
    from flexgear.modal.linear import _component_name

    return _component_name(body)
