"""The check of a flexible variant's linearised modes against the same assembly with full FE bodies.

At zero speed (no spin terms) three sets of undamped natural frequencies f = sqrt(s) / (2 pi) below ``f_max``:

- ``model``: the variant's linear model as it is (flexgear.modal.linear.linearize: reduced bodies, the gears'
  modes above the dynamic cut-off as residual compliance);
- ``all_modes``: the same with every mode of the bodies' bases kept (no residual compliance); the couplings of
  the reference are recovered from this linearisation (flexgear.modal.full_fe.recover), and its frequencies
  recomputed from the recovered couplings (``recovery``: their largest relative difference) check that step;
- ``full``: every flexible body replaced by its full FE model (flexgear.modal.full_fe), with the same bearings,
  joints and tangent mesh springs at the static deflection of the all-modes operating point. A body with fewer
  modes than attachment motions (a short shaft whose basis holds few modes below the cutoff) cannot give its
  couplings back from the linearisation; it stays reduced in every set (``kept_reduced``).

Modes are paired by shape and frequency together (:func:`_pairs`); the reduced bodies are Ritz approximations, each
frequency an upper bound of the full model's in the same order.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

from flexgear.fe.patches import rigid_interfaces
from flexgear.modal.full_fe import (
    assembled,
    attachments,
    body_fe_model,
    carries_attachments,
    eigenvalues,
    full_flexibility,
    recover,
    reduced_flexibility,
)
from flexgear.spec import Variant

__all__ = ["FullFEComparison", "compare_full_fe", "default_f_max_hz"]


@dataclass
class FullFEComparison:
    """Frequencies [Hz] (module docstring), each (n,) ascending; ``recovery`` and ``leak`` (relative) the checks of
    the couplings' recovery; ``deflection_change``: the largest relative difference of the contacts' static
    deflections between the model and the all-modes linearisation; ``seconds``: wall time per step; ``bodies``:
    {body: (attachment motions, its full FE free-free modes below f_max, the reduced body's, series terms)};
    ``mac``: the modal assurance criterion of each pair on the common coordinates; ``unpaired``: the full
    assembly's frequencies below f_max [Hz] without a reduced partner (modes the reduced bases leave out), and
    ``unpaired_bodies`` the body whose full FE modes carry each; ``model_frequencies`` [Hz] the model's own
    below f_max (``model`` holds them in order where the model has as many modes as the all-modes one, else NaN).
    """

    variant: str
    f_max_hz: float
    model: np.ndarray
    all_modes: np.ndarray
    full: np.ndarray
    recovery: float
    leak: float
    deflection_change: float
    seconds: dict[str, float]
    bodies: dict[str, tuple[int, int, int, int]] = dataclasses.field(default_factory=dict)
    mac: np.ndarray | None = None
    unpaired: np.ndarray | None = None
    unpaired_bodies: list[str] = dataclasses.field(default_factory=list)
    model_frequencies: np.ndarray | None = None
    kept_reduced: list[str] = dataclasses.field(default_factory=list)

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
                 f"{'all-modes err %':>16} {'MAC':>6}"]
        mac = np.full(len(self.full), np.nan) if self.mac is None else self.mac
        for i, (a, b, c) in enumerate(zip(self.model, self.all_modes, self.full, strict=True)):
            lines.append(f"{i + 1:4d} {a:12.3f} {b:15.3f} {c:13.3f} {100 * (a / c - 1):12.4f} "
                         f"{100 * (b / c - 1):16.4f} {mac[i]:6.3f}")
        lines.append(f"max |model err| {100 * np.abs(self.error).max():.4f} %, max |all-modes err| "
                     f"{100 * np.abs(self.basis_error).max():.4f} %, recovery {self.recovery:.1e}, "
                     f"leak {self.leak:.1e}, static deflection change {self.deflection_change:.1e}")
        if self.model_frequencies is not None and np.isnan(self.model).any():
            lines.append(f"the model has {len(self.model_frequencies)} modes below f_max, the all-modes one "
                         f"{len(self.all_modes)} [Hz]: " + " ".join(f"{f:.1f}" for f in self.model_frequencies))
        if self.kept_reduced:
            lines.append(f"left reduced (fewer modes than attachment motions): {', '.join(self.kept_reduced)}")
        if self.unpaired is not None and len(self.unpaired):
            lines.append(f"{len(self.unpaired)} full-FE assembly modes below f_max without a reduced partner [Hz, "
                         "body]: " + ", ".join(f"{f:.0f} {b}" for f, b in zip(self.unpaired, self.unpaired_bodies,
                                                                               strict=False)))
        for name, (n_a, n_full, n_red, n_terms) in self.bodies.items():
            lines.append(f"  {name}: {n_a} attachment motions; free-free modes below f_max: full FE {n_full}, "
                         f"reduced {n_red}; {n_terms} series terms")
        return "\n".join(lines)


def default_f_max_hz(variant: Variant) -> float:
    """Three times the mesh frequency at the load case's input speed [Hz]."""
    from flexgear.theory import theory

    return 3.0 * theory(variant.gearbox).mesh_frequency


def _frequencies(model, s_max: float) -> np.ndarray:
    from scipy.linalg import eigh

    w2 = eigh(model.stiffness, model.mass, eigvals_only=True)
    return w2[(w2 > 0.0) & (w2 <= s_max)]


PAIRING_FREQUENCY_SCALE = 0.01
"""Relative frequency distance that weighs as much as a full loss of shape similarity in the pairing (:func:`_pairs`):
two modes 1 % apart cost as much as two with MAC 0."""


def _pairs(x_red: np.ndarray, x_full: np.ndarray, common: slice, s_red: np.ndarray,
           s_full: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each reduced mode, its full partner: the assignment of least total (1 - MAC) + |ln(f_red / f_full)| /
    :data:`PAIRING_FREQUENCY_SCALE`, the MAC on the ``common`` coordinates (r and the attachment motions a, the same
    in both problems), one full mode per reduced mode at most. The shape alone is ambiguous where a body's modes
    barely move the attachments (a thin ring's), the frequency alone where modes cluster. Returns (indices, MAC)."""
    from scipy.optimize import linear_sum_assignment

    a = x_red[common] / np.maximum(np.linalg.norm(x_red[common], axis=0), 1e-300)
    b = x_full[common] / np.maximum(np.linalg.norm(x_full[common], axis=0), 1e-300)
    mac = (a.T @ b) ** 2
    distance = np.abs(0.5 * np.log(np.maximum(s_red, 1e-300)[:, None] / np.maximum(s_full, 1e-300)[None, :]))
    rows, cols = linear_sum_assignment((1.0 - mac) + distance / PAIRING_FREQUENCY_SCALE)
    out = np.full(a.shape[1], -1)
    out[rows] = cols
    return out, mac[np.arange(a.shape[1]), out]


def compare_full_fe(variant: Variant, f_max_hz: float | None = None, progress=None,
                    cache: dict | None = None, hold_rigid_patches: bool = True) -> FullFEComparison:
    """:class:`FullFEComparison` of ``variant`` at zero speed below ``f_max_hz`` (default
    :func:`default_f_max_hz`). ``hold_rigid_patches``: False leaves the interfaces the reductions hold rigid free to
    deform in the full FE models (RBE3): the effect of that assumption, not a check of the reduction.
    ``progress``: a callable taking a message, or None; ``cache``: a dict that keeps
    the full FE flexibilities between calls (they depend on the mesh, the attachments and ``f_max_hz`` only)."""
    from flexgear.modal.linear import linearize

    say = progress or (lambda msg: None)
    f_max = default_f_max_hz(variant) if f_max_hz is None else float(f_max_hz)
    s_max = (2 * np.pi * f_max) ** 2
    s_top = 1.05 * s_max  # the full set reaches above the reduced one's top: its partners may lie higher
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
    every = attachments(all_model)  # the couplings of the all-modes model, before its elimination
    bodies = [b for b in every if carries_attachments(b)]
    coupled = recover(all_model, bodies)
    s_all = _frequencies(all_model, s_max)
    s_rec, x_rec = eigenvalues(*assembled(coupled, [reduced_flexibility(b) for b in bodies])[:2], s_max=s_max)
    recovery = float(np.abs(np.sqrt(s_rec / s_all) - 1.0).max()) if len(s_rec) == len(s_all) else np.inf
    seconds["recover"] = time.perf_counter() - t
    t = time.perf_counter()
    cache = {} if cache is None else cache
    flex, fe_cache, done = [], {}, {}
    for b in bodies:
        name = next(nm for nm, body in all_model.bodies.items() if body.flexible and _component(nm) == b.component)
        body = all_model.bodies[name]
        fe_key = "planet" if name.startswith("planet") else name
        rigid = tuple(itf.nodes for itf in rigid_interfaces(body.reduced)) if hold_rigid_patches else ()
        key = (variant.mesh_level, fe_key, b.weights.indices.tobytes(), np.round(b.weights.data, 12).tobytes(),
               s_top, tuple(r.tobytes() for r in rigid))
        if key not in cache:
            if fe_key not in fe_cache:
                say(f"  {name}: full FE model")
                fe_cache = {fe_key: body_fe_model(variant.gearbox, name, body.reduced, variant.mesh_level)}
            say(f"  {name}: full FE flexibility at {b.weights.shape[1]} attachment motions")
            cache[key] = full_flexibility(fe_cache[fe_key], b.weights, s_top, body.reduced.frequencies_hz,
                                          rigid=rigid)
        f = cache[key]
        done[name] = (b.weights.shape[1], int(np.count_nonzero(f.eigenvalues <= s_max)),
                      int(np.count_nonzero((2 * np.pi * body.reduced.frequencies_hz) ** 2 <= s_max)), len(f.moments))
        flex.append(f)
    seconds["full FE bodies"] = time.perf_counter() - t
    t = time.perf_counter()
    t0, t1, rest = assembled(coupled, flex)
    s_full, x_full = eigenvalues(t0, t1, rest, s_max=s_top)
    seconds["assembled eigenvalues"] = time.perf_counter() - t
    s_model = _frequencies(model, s_max)
    model_hz = np.sqrt(s_model) / (2 * np.pi)
    if len(s_model) != len(s_all):  # the model's own frequencies are listed apart: no pairing by order
        s_model = np.full(len(s_all), np.nan)
    n_common = len(coupled.rest) + coupled.c_r.shape[0] + coupled.n_attachments
    common_rows = np.r_[0:len(coupled.rest), len(coupled.rest) + coupled.c_r.shape[0]:n_common]
    pair, mac = _pairs(x_rec, x_full, common_rows, s_rec, s_full)
    unpaired = np.setdiff1d(np.flatnonzero(s_full <= s_max), pair)
    hz = [np.sqrt(s) / (2 * np.pi) for s in (s_model, s_all, s_full[pair])]
    owners = _owners(coupled, flex, [b.component for b in bodies], x_full[:, unpaired])
    return FullFEComparison(variant.name, f_max, *hz, recovery, coupled.leak, change, seconds, done, mac,
                            np.sqrt(s_full[unpaired]) / (2 * np.pi), owners, model_hz,
                            [b.component for b in every if not carries_attachments(b)])


def _owners(coupled, flex: list, names: list[str], x: np.ndarray) -> list[str]:
    """For each mode x of the full assembly, the body whose full FE modes eta carry most of it."""
    start = len(coupled.rest) + coupled.c_r.shape[0] + 2 * coupled.n_attachments
    share = []
    for f in flex:
        n = f.participation.shape[1]
        share.append(np.linalg.norm(x[start:start + n], axis=0))
        start += n
    share = np.array(share).reshape(len(flex), -1)
    return [names[i] for i in np.argmax(share, axis=0)] if share.size else []


def _component(body: str) -> str:
    from flexgear.modal.linear import component_name

    return component_name(body)
