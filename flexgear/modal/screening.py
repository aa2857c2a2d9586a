"""Modal screening: which components must be flexible, from the modes of the all-flexible variant.

The all-flexible variant (Table 3's model 7) is linearised at its operating point (flexgear.modal.linear) and its
modes are taken within the excitation band of the load case, 0 < f <= f_band = 10 f_m (f_m the mesh frequency at
the operating speed, flexgear.theory; the mesh excitation's harmonics 1x to 10x), leaving out roots without a
resonance peak (damping ratio zeta >= 1/sqrt(2), flexgear.modal.campbell_diagram).

Elastic share. For a component c and a mode j, s_cj is the share of the mode's strain energy in c's own elastic
coordinates (flexgear.modal.eigenmodes: column ``strain_<c>_elastic``; the planets' shares are added into one component,
``planets``, as in Table 3; a component that is rigid in the variant has none: s_cj = 0, and it is not judged: the
screening cannot see whether its deformation matters, so it is marked so, never "may be rigid", and the reason names
it. A variant with no flexible component is refused).

Weight. A mode matters as much as the mesh excitation can amplify it: a harmonic force at k f_m drives mode j (a
single degree of freedom, frequency f_j, damping ratio zeta_j) with the dynamic amplification

    A(r) = 1 / sqrt((1 - r^2)^2 + (2 zeta_j r)^2),    r = k f_m / f_j,

over its static response. Mode j's weight is A at the harmonic nearest to resonance (the largest over k = 1..10),
normalised over the modes of the band, w_j = A_j / sum_i A_i. A mode at a harmonic counts 1/(2 zeta_j) times its
quasi-static weight; a mode far above every harmonic (r -> 0) counts like a static one, A = 1, since the
excitation's static part loads it too; one far below them counts 1/r^2, little. The weighted elastic share is

    S_c = sum_j w_j s_cj            (in [0, 1]: the w_j sum to 1, each s_cj is in [0, 1]).

Decision. Treating c as rigid removes its elastic compliance from every mode: where c's elastic strain holds the
share s of a mode's strain energy, c acts as a spring in series with the rest, and the rigid model's frequency is
higher by the factor 1/sqrt(1 - s) (Rayleigh's quotient, omega^2 = U / T at the same kinetic energy T with the
compliance 1/k_c removed). c must be flexible where S_c exceeds ``threshold`` (default :data:`THRESHOLD` = 0.05: a
frequency error of 1/sqrt(0.95) - 1 = 2.6 %, the half-power bandwidth 2 zeta of a mesh mode damped at zeta = 1.3 %,
i.e. the rigid model would move a resonance out of the band in which the flexible model's response is within a
factor sqrt(2) of its peak).

Recommendation. The variant (of the same gear set, beside the given one: Table 3's model_variants/model1.toml ...
model7.toml for the study; or the matrix's variants) with the fewest flexible components that has every component
that must be flexible flexible (the first on a tie: Table 3's lower model number); the one with the most flexible
components if none has them all.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from flexgear.modal import LinearModel, Modes
from flexgear.schema import OPTIONAL_COMPONENTS, Variant, stage_components

__all__ = ["ModalScreening", "modal_screening", "amplification", "folder_variants", "flexible_components", "THRESHOLD",
           "TABLE3_COMPONENTS"]

THRESHOLD = 0.05
"""Weighted elastic strain share above which a component must be flexible (module docstring: 2.6 % frequency)."""

TABLE3_COMPONENTS = ("input_shaft", "sun", "planets", "ring", "output_shaft")
"""Table 3's components (a variant file's ``[components]``); ``planets`` stands for planet_1 ... planet_N."""

_TABLE3 = re.compile(r"^model(\d+)\.toml$")


def _amplifications(f_hz: np.ndarray, zeta: np.ndarray, f_mesh_hz: float, orders: int = 10) -> np.ndarray:
    """A(r) of each mode (rows) at each harmonic k f_m, k = 1..``orders`` (columns) (module docstring)."""
    k = np.arange(1, orders + 1)
    r = k[None, :] * f_mesh_hz / np.asarray(f_hz, float)[:, None]
    z = np.asarray(zeta, float)[:, None]
    return 1.0 / np.sqrt((1.0 - r**2) ** 2 + (2.0 * z * r) ** 2)


def amplification(f_hz: np.ndarray, zeta: np.ndarray, f_mesh_hz: float, orders: int = 10) -> np.ndarray:
    """Largest dynamic amplification A(r) over the harmonics k f_m, k = 1..``orders``, of each mode (frequencies
    ``f_hz`` [Hz], damping ratios ``zeta`` [-]) under the mesh frequency ``f_mesh_hz`` [Hz] (module docstring)."""
    return _amplifications(f_hz, zeta, f_mesh_hz, orders).max(axis=1)


def _table3_component(component: str) -> str:
    return "planets" if component.startswith("planet_") else component


@dataclass(frozen=True)
class ModalScreening:
    """The screening's result (module docstring).

    ``table``: component (Table 3's, and the planetary stage's carrier where it is flexible),
    weighted_elastic_strain_share [-], judged (flexible in the screened variant), must_be_flexible;
    ``recommended``: the recommended variant's name; ``reason``: one line; ``modes``: the modes of the band;
    ``weighted``: the indices of those with a resonance peak, ``weights``: their w_j; ``f_mesh_hz``, ``f_band_hz``
    [Hz], ``threshold`` [-]; ``candidates``: Table 3's variants {name: flexible components}.
    """

    table: pd.DataFrame
    recommended: str
    reason: str
    modes: Modes
    weighted: np.ndarray
    weights: np.ndarray
    f_mesh_hz: float
    f_band_hz: float
    threshold: float
    candidates: dict[str, tuple[str, ...]]

    def mode_table(self) -> pd.DataFrame:
        """One row per weighted mode (a resonance peak in the band): mode (1-based, of the band), frequency_hz,
        damping_ratio, kind, ``harmonic`` k (the mesh harmonic k f_m nearest to resonance, the largest A(r)),
        ``weight`` w_j, and each Table 3 component's elastic strain share s_cj (``share_<component>``), the planets
        added into one."""
        f = self.modes.frequencies_hz[self.weighted]
        zeta = np.maximum(self.modes.damping_ratios[self.weighted], 0.0)
        a = _amplifications(f, zeta, self.f_mesh_hz)
        out = pd.DataFrame({"mode": np.asarray(self.weighted) + 1, "frequency_hz": f, "damping_ratio": zeta,
                            "kind": [self.modes.kinds[i] for i in self.weighted], "harmonic": a.argmax(axis=1) + 1,
                            "weight": self.weights})
        screened = tuple(self.table.component)
        for c in screened:
            out[f"share_{c}"] = 0.0
        for column in self.modes.energy.columns:
            if column.startswith("strain_") and column.endswith("_elastic"):
                c = _table3_component(column.removeprefix("strain_").removesuffix("_elastic"))
                if c in screened:
                    out[f"share_{c}"] += self.modes.energy[column].to_numpy()[self.weighted]
        return out


def folder_variants(folder: Path, gears: object | None = None) -> dict[str, tuple[str, ...]]:
    """The variant files in ``folder`` (every ``*.toml`` that loads as a variant, of the gear set ``gears``
    (flexgear.schema.GearSet) when given): {name: its flexible components}, Table 3's ``model<number>.toml`` first in
    number order, the others by file name."""
    from flexgear.spec import SpecError, load_variant

    def order(p: Path) -> tuple:
        match = _TABLE3.match(p.name)
        return (0, int(match.group(1)), "") if match else (1, 0, p.name)

    out = {}
    for path in sorted(Path(folder).glob("*.toml"), key=order):
        try:
            v = load_variant(path)
        except (SpecError, OSError, ValueError):  # not a variant file (a gearbox file, a sweep file)
            continue
        if gears is None or v.gearbox.gears == gears:
            out[v.name] = flexible_components(v)
    return out


def flexible_components(variant: Variant) -> tuple[str, ...]:
    """The components ``variant`` makes flexible, in Table 3's order (the carrier last)."""
    return tuple(c for c in (*TABLE3_COMPONENTS, *OPTIONAL_COMPONENTS) if variant.components.get(c) == "flexible")


def recommend(must: tuple[str, ...], candidates: dict[str, tuple[str, ...]]) -> tuple[str, str]:
    """(name, one-line reason): the candidate with the fewest flexible components that holds all of ``must``, the
    first of them on a tie; the one with the most flexible components if none holds them all."""
    if not candidates:
        return "", (f"{', '.join(must) or 'no component'} must be flexible; no variant of this gear set beside it "
                    "to recommend")
    fits = [name for name, flexible in candidates.items() if set(must) <= set(flexible)]
    if fits:
        name = min(fits, key=lambda n: len(candidates[n]))
        what = ", ".join(must) if must else "no component"
        flexible = ", ".join(candidates[name]) or "none"
        return name, (f"{what} must be flexible; {name} is the variant with the fewest flexible "
                      f"components ({flexible}) that has them")
    name = max(candidates, key=lambda n: len(candidates[n]))
    return name, f"{', '.join(must)} must be flexible; no variant has them all but {name}"


def modal_screening(variant_flexible_all: Variant | LinearModel, f_band_hz: float | None = None, *,
                    threshold: float = THRESHOLD, variants_dir: str | Path | None = None,
                    candidates: dict[str, tuple[str, ...]] | None = None) -> ModalScreening:
    """Screen the components of ``variant_flexible_all`` (Table 3's model 7, or its :class:`LinearModel` at the
    operating point) by their weighted elastic strain share (module docstring).

    ``f_band_hz`` [Hz]: the excitation band (default 10 f_m at the load case's input speed); ``threshold`` [-]:
    the share above which a component must be flexible; ``candidates`` {name: flexible components}: the variants
    to recommend from (default :func:`folder_variants` of ``variants_dir``, the variant file's own folder when
    None, of its gear set).
    """
    from flexgear.modal import linearize, mesh_frequency_hz, modes, resonant

    linear = isinstance(variant_flexible_all, LinearModel)
    given = variant_flexible_all.variant if linear else variant_flexible_all
    flexible = flexible_components(given)
    if not flexible:  # before the linearisation: nothing to judge
        raise ValueError(f"{given.source}: field 'components': the modal screening judges the components a variant "
                         f"makes flexible and {given.name} makes none flexible; screen the all-flexible variant "
                         "(Table 3's model 7)")
    model = variant_flexible_all if linear else linearize(given)
    variant = model.variant
    f_mesh = mesh_frequency_hz(variant.gearbox, model.speed_rpm)
    band = 10.0 * f_mesh if f_band_hz is None else float(f_band_hz)
    if not band > 0.0:
        raise ValueError(f"the excitation band must be above 0 Hz, got {band:g} Hz "
                         f"(input speed {model.speed_rpm:g} rpm)")
    found = modes(model, band)
    keep = resonant(found)
    f, zeta = found.frequencies_hz[keep], found.damping_ratios[keep]
    weights = amplification(f, np.maximum(zeta, 0.0), f_mesh)
    weights = weights / weights.sum() if weights.size else weights
    # Table 3's components of the arrangement (no ring in a pair), and an optional one (the planetary stage's
    # carrier) where the model has it
    shares = dict.fromkeys((*(c for c in TABLE3_COMPONENTS if c in stage_components(variant.gearbox.gears)),
                            *(c for c in OPTIONAL_COMPONENTS if c in model.components)), 0.0)
    for c in model.components:
        column = f"strain_{c}_elastic"
        if column in found.energy:
            shares[_table3_component(c)] += float(weights @ found.energy[column].to_numpy()[keep])
    table = pd.DataFrame({"component": list(shares), "weighted_elastic_strain_share": list(shares.values())})
    table["judged"] = table.component.isin(flexible)
    table["must_be_flexible"] = table.judged & (table.weighted_elastic_strain_share > threshold)
    must = tuple(table.component[table.must_be_flexible])
    if candidates is None:
        folder = Path(variants_dir) if variants_dir is not None else Path(variant.source).parent
        candidates = folder_variants(folder, variant.gearbox.gears)
    name, reason = recommend(must, candidates)
    unseen = tuple(table.component[~table.judged])
    if unseen:
        reason += f"; not judged, rigid in {variant.name}: {', '.join(unseen)}"
    return ModalScreening(table, name, reason, found, keep, weights, f_mesh, band, threshold, candidates)
