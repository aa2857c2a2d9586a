"""How close are the reduced bodies to full FE: for each component, how many attachment orders and fixed-interface
modes does the contact compliance and the free-free spectrum need? (The tied ring and output shaft against full
FE: benchmarks/bench_tied.py.)

Run: python benchmarks/bench_convergence.py [--level coarse] [--orders 0 2 4 8] [--modes 0 10 20 40]
                                            [--kernel-orders 4 8 16 32] [component ...]
     python benchmarks/bench_convergence.py --assembly [model7] [--f-max HZ]

Per component (sun, planet, ring; shafts: frequencies only), all on the same FE model, interface held
as the gear's joint (RBE3, flexgear.fe.compliance):

- kernel compliance: the full FE compliance matrix C under the contact kernel's loads (order
  ``contact_fourier_order`` of gearbox.toml) at every contact of the body, against the reduced body's
  for each attachment order N and fixed-interface mode count: the mean ratio of the row sums (all
  contacts loaded together, as in the gearbox) and the largest entry error max|C_red - C|/max|C|;
- free frequencies: the largest relative error of the reduced body's 12 lowest free-free frequencies
  against the full model's (same solver);
- remainder: the full FE compliance of one contact under a tooth-normal force spread area-weighted over
  the surface within half a helix width of the pitch point, minus the full FE kernel compliance of
  order K (the part above the kernel, local: tooth bending, foundation), for each K, against the tooth
  compliance of the ISO 6336 mesh stiffness 1 / (c_gamma b_half) ([lumped_assumed] of gearbox.toml)
  and the study's impact law linearised at the theoretical mean mesh force per half.

``--assembly VARIANT``: the variant's linearised modes at zero speed below 3x the mesh frequency (``--f-max``)
against the same assembly with every flexible body as its full FE model (flexgear.modal.full_fe_check): the
table of the model's (residual compliance), the all-modes basis' and the full FE frequencies.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

COMPONENTS = ("sun", "planet", "ring", "input_shaft", "output_shaft")
N_FREQ = 12

CRITERION = 0.05  # the ring-output shaft joint: first ten modes within 5 % of full FE
N_JOINT_MODES = 10


def _fe(spec, component: str, level: str):
    from flexgear.fe.fem import fe_model
    from flexgear.fe.mesh import component_mesh

    mesh = component_mesh(spec, component, level, order=1)
    return fe_model(mesh.ngsolve_mesh(), spec.material_assumed, spec.meshing_assumed[level].element_order)


def _subset(parts, circles: int, order: int, max_order: int, n_fixed: int) -> np.ndarray:
    """Basis columns: static modes, the lowest n_fixed fixed-interface modes, attachment modes to ``order``."""
    per = 2 * max_order + 1
    cols = [np.arange(k * per, k * per + 2 * order + 1) for k in range(circles)]
    cols = np.concatenate(cols) if cols else np.zeros(0, int)
    return np.hstack([parts.static, parts.fixed[:, :n_fixed], parts.attached[:, cols]])


def tooth_compliances(spec) -> tuple[float, float]:
    """Per helix half [m/N]: ISO 6336 1 / (c_gamma b_half); the study's law dF/d(delta) at the mean force."""
    from flexgear.geometry.involute import gear_set_geometry
    from flexgear.laws.contact import ContactLaw
    from flexgear.theory import theory

    geo = gear_set_geometry(spec)
    b_half = geo.helix_face_width
    iso = 1.0 / (spec.lumped_assumed.mesh_stiffness_per_width_n_per_mm_um * 1e9 * b_half)
    share = b_half / spec.gears_assumed.face_width_m
    law = ContactLaw.from_contact(spec.contact, share)
    force = theory(spec).mesh_force * share
    delta = (force / law.stiffness) ** (1.0 / law.exponent)
    return iso, delta / (law.exponent * force)


def study(spec, component: str, level: str, orders: list[int], modes: list[int], kernel_orders: list[int]) -> None:
    from flexgear.fe.attachment import modal_basis
    from flexgear.fe.cms import ReducedBody, full_free_modes, reduction_basis
    from flexgear.fe.compliance import free_body_solver, static_compliance
    from flexgear.fe.reduced import component_contacts, component_interfaces, component_load_circles

    t0 = time.perf_counter()
    fe = _fe(spec, component, level)
    # the component's own interfaces (the ring's and output shaft's bolt patches as RBE3 here); the study holds
    # the body at its first interface
    itfs = component_interfaces(fe, spec, component)
    solver = free_body_solver(fe)
    gear = component in ("sun", "planet", "ring")
    max_order = max(orders) if gear else 0
    circles = component_load_circles(spec, component, max_order) if gear else []
    parts = reduction_basis(fe, itfs, max(modes), "rbe3", circles, solver=solver)
    f_full = full_free_modes(fe, N_FREQ, solver)[0]
    print(f"\n== {component} ({level}): {fe.n_dof} dof, {len(circles)} contact bands, "
          f"full FE f1..f{N_FREQ} = {np.round(f_full[[0, -1]])} Hz  [{time.perf_counter() - t0:.0f} s]", flush=True)
    held = itfs[0]
    if gear:
        points, normals = component_contacts(spec, component)
        kernel_order = spec.reduction_assumed.contact_fourier_order
        kernel = component_load_circles(spec, component, kernel_order)
        c_full = static_compliance(fe, points, normals, held, kernel=kernel)
        print(f"kernel order {kernel_order}, {len(points)} contacts, held {held.name!r}: full FE all-loads "
              f"compliance {np.mean(c_full.sum(1)):.3e} m/N, single contact {np.mean(np.diag(c_full)):.3e} m/N")
    print(f"{'order N':>8} {'fixed':>6} {'modes':>6} {'C_red/C (all loads)':>20} {'max entry err':>14} "
          f"{'max f err (12)':>15}")
    for order in (orders if gear else [0]):
        for n_fixed in modes:
            basis = _subset(parts, len(circles), order if gear else -1, max_order, n_fixed)
            shapes, lam, _ = modal_basis(basis, fe.K, fe.M)
            freq = np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi)
            f_err = np.max(np.abs(freq[:N_FREQ] / f_full - 1)) if len(freq) >= N_FREQ else np.nan
            line = f"{order if gear else '-':>8} {n_fixed:>6} {len(lam):>6}"
            if gear:
                body = ReducedBody(fe.nodes, shapes, lam, freq, f_full, itfs, "rbe3", n_fixed, None, {},
                                   fe.surface_triangles)
                c_red = static_compliance(body, points, normals, held, kernel=kernel)
                ratio = np.mean(c_red.sum(1) / c_full.sum(1))
                err = np.max(np.abs(c_red - c_full)) / np.max(np.abs(c_full))
                line += f" {ratio:>20.4f} {err:>14.2e}"
            else:
                line += f" {'-':>20} {'-':>14}"
            print(line + f" {f_err:>15.2e}", flush=True)
    if gear:
        iso, law = tooth_compliances(spec)
        radius = 0.5 * (kernel[0].z_max_m - kernel[0].z_min_m)
        c_spread = static_compliance(fe, points[:1], normals[:1], held, spread_radius_m=radius)[0, 0]
        print(f"remainder above kernel order K (contact 1; patch load within {radius * 1e3:.1f} mm: "
              f"{c_spread:.3e} m/N); tooth compliance per half: ISO 6336 {iso:.3e}, study's law {law:.3e} m/N")
        for k in kernel_orders:
            ck = static_compliance(fe, points[:1], normals[:1], held,
                                   kernel=component_load_circles(spec, component, k))[0, 0]
            rem = c_spread - ck
            print(f"  K = {k:>3}: kernel {ck:.3e}  remainder {rem:.3e} m/N = {rem / iso:.3f} x ISO tooth, "
                  f"{rem / law:.4f} x study's law", flush=True)
    print(f"[{component} done in {time.perf_counter() - t0:.0f} s]", flush=True)


def assembly(name: str, f_max_hz: float | None) -> None:
    """Print the full-FE assembly check of variant ``name`` (module docstring)."""
    from pathlib import Path

    from flexgear.modal.full_fe_check import compare_full_fe
    from flexgear.spec import load_variant

    t0 = time.perf_counter()
    variant = load_variant(Path(__file__).resolve().parents[1] / "model_variants" / f"{name}.toml")
    result = compare_full_fe(variant, f_max_hz, progress=lambda msg: print(msg, flush=True))
    print(result.table())
    print("  ".join(f"{k} {v:.0f} s" for k, v in result.seconds.items()) + f"  [{time.perf_counter() - t0:.0f} s]")


def main() -> None:
    from pathlib import Path

    from flexgear.spec import load_gearbox

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("components", nargs="*", default=list(COMPONENTS[:3]), choices=COMPONENTS)
    ap.add_argument("--level", default="coarse")
    ap.add_argument("--orders", type=int, nargs="+", default=[0, 2, 4, 6, 8])
    ap.add_argument("--modes", type=int, nargs="+", default=[0, 10, 20, 40])
    ap.add_argument("--kernel-orders", type=int, nargs="*", default=[4, 8, 16, 32])
    ap.add_argument("--gearbox", default=str(Path(__file__).resolve().parents[1] / "model_variants/gearbox.toml"))
    ap.add_argument("--assembly", nargs="?", const="model7", default=None, metavar="VARIANT",
                    help="compare the variant's linearised modes with the full-FE assembly (default model7)")
    ap.add_argument("--f-max", type=float, default=None, help="highest frequency [Hz] (default 3x mesh frequency)")
    args = ap.parse_args()
    if args.assembly:
        assembly(args.assembly, args.f_max)
        return
    spec = load_gearbox(args.gearbox)
    for component in args.components:
        study(spec, component, args.level, sorted(args.orders), sorted(args.modes), args.kernel_orders)


if __name__ == "__main__":
    main()
