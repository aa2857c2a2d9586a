"""How close are the reduced bodies to full FE: for each component, how many attachment orders and fixed-interface
modes does the contact compliance and the free-free spectrum need? (The tied ring and output shaft against full
FE: benchmarks/bench_tied.py.)

Run: python benchmarks/bench_convergence.py [--level coarse] [--orders 0 2 4 8] [--modes 0 10 20 40]
                                            [--kernel-orders 4 8 16 32] [component ...]
     python benchmarks/bench_convergence.py --assembly [model7] [--f-max HZ]
     python benchmarks/bench_convergence.py --band [--cutoff-orders 3 3.5 4 5] [--band-orders 3] [body ...]

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

``--band``: for each body (the components, and "tied": the ring and output shaft reduced together), the basis of
the production reduction with every fixed-interface mode below each of ``--cutoff-orders`` x the mesh frequency
(``[reduction_assumed] fixed_interface_cutoff_hz`` in mesh orders): its fixed-interface mode count, coordinates, and its
free-free modes below ``--band-orders`` x the mesh frequency against the full FE model's (the largest error, the
first more than 1 % off, full FE modes without a partner). A body with a rigid interface (the ring or the output
shaft alone: its bolt patches joined to the rigid partner) is compared with its full FE model with those patches
rigid.

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


def _body_fe(spec, body: str, level: str):
    """FE model, interfaces, load circles and rigid interfaces of ``body`` as the production reduction has them."""
    from flexgear.fe.reduced import BOLT_PATCHES, component_interfaces, component_load_circles
    from flexgear.fe.ring_shaft import pair_fe_models, part_fe_model, tied_pair, tied_pair_interfaces

    order = spec.reduction_assumed.attachment_order
    if body == "tied":
        ring, shaft = pair_fe_models(spec, level)
        tied = tied_pair(ring, shaft, spec)
        return tied.fe, tied_pair_interfaces(tied, shaft, spec), component_load_circles(spec, "ring", order), ()
    fe = part_fe_model(spec, body, level)
    itfs = component_interfaces(fe, spec, body)
    return fe, itfs, component_load_circles(spec, body, order), tuple(i.name for i in itfs if i.name == BOLT_PATCHES)


def _patch_reference(fe, itfs, rigid: tuple[str, ...], f_max_hz: float) -> np.ndarray:
    """Flexible free-free frequencies [Hz] below ``f_max_hz`` of the full FE model whose ``rigid`` interfaces' nodes
    each move as one rigid body (the physics a rigid-patch reduction stands for: joined to a rigid partner)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as sla

    from flexgear.fe.fem import rigid_body_modes
    from flexgear.fe.spectrum import lowest_eigenpairs

    patches = [i for i in itfs if i.name in rigid]
    bdofs = np.concatenate([(3 * i.nodes[:, None] + np.arange(3)).ravel() for i in patches])
    idofs = np.setdiff1d(np.arange(fe.n_dof), bdofs)
    rows, cols, vals = [idofs], [np.arange(idofs.size)], [np.ones(idofs.size)]
    for j, itf in enumerate(patches):
        r = rigid_body_modes(fe.nodes[itf.nodes], centre=itf.point)  # (3k, 6)
        dofs = (3 * itf.nodes[:, None] + np.arange(3)).ravel()
        rr, cc = np.nonzero(r)
        rows.append(dofs[rr]), cols.append(idofs.size + 6 * j + cc), vals.append(r[rr, cc])
    t = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(fe.n_dof, idofs.size + 6 * len(patches)))
    k, m = (t.T @ fe.K @ t).tocsc(), (t.T @ fe.M @ t).tocsc()

    def eigen(n: int, found: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:  # the n pairs beyond ``found``
        j = 0 if found is None else found.shape[1]
        lam, vec = sla.eigsh(k, k=j + n + 6, M=m, sigma=-1.0, which="LM", tol=1e-10)
        order = np.argsort(lam)[6 + j:]  # past the six rigid-body modes and those found
        return lam[order], vec[:, order]

    lam = lowest_eigenpairs(eigen, max_hz=f_max_hz)[0]
    return np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi)


def band(spec, body: str, level: str, cutoff_orders: list[float], band_orders: float,
         verbose: bool = False) -> list[dict]:
    """Free-free modes below ``band_orders`` x f_mesh of ``body`` reduced with each fixed-interface cutoff against
    full FE (module docstring, ``--band``)."""
    from flexgear.fe.attachment import modal_basis
    from flexgear.fe.cms import FreeBodySolver, reduction_basis
    from flexgear.fe.spectrum import lowest_eigenpairs
    from flexgear.modal import mesh_frequency_hz

    f_mesh = mesh_frequency_hz(spec, spec.load_case.input_speed_rpm)
    f_band = band_orders * f_mesh
    t0 = time.process_time()
    fe, itfs, circles, rigid = _body_fe(spec, body, level)
    m = fe.mass_operator()
    solver = None if rigid else FreeBodySolver(fe)
    free = None if rigid else solver.constrained((m @ solver.R).T)
    if rigid:  # the reference holds the rigid patches rigid too
        full = _patch_reference(fe, itfs, rigid, 1.02 * f_band)
    else:
        full = np.sqrt(np.maximum(lowest_eigenpairs(lambda k, found, below=None: free.eigen(fe, k, m, found, below),
                                                     max_hz=1.02 * f_band)[0], 0.0))
        full /= 2 * np.pi
    full = full[full < f_band]
    parts = reduction_basis(fe, itfs, None, "rbe3", circles, solver=solver, rigid=rigid,
                            max_hz=max(cutoff_orders) * f_mesh)
    f_fixed = np.sqrt(np.maximum(np.einsum("ij,ij->j", parts.fixed, fe.K @ parts.fixed), 0.0)) / (2 * np.pi)
    rows = []
    for c in sorted(cutoff_orders):
        keep = f_fixed < c * f_mesh
        modes, lam, _ = modal_basis(np.hstack([parts.static, parts.fixed[:, keep], parts.attached]), fe.K, m)
        red = np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi)
        k = min(full.size, red.size)
        err = red[:k] / full[:k] - 1.0
        if verbose:
            print("   ", " ".join(f"{a:.0f}/{b:.0f}" for a, b in zip(red[:k], full[:k], strict=True)))
        off = np.flatnonzero(np.abs(err) > 0.01)
        row = {"body": body, "cutoff_orders": c, "fixed_interface_modes": int(keep.sum()), "modes": int(red.size),
               "full_below": int(full.size), "reduced_below": int(np.count_nonzero(red < f_band)),
               "largest_error_pct": float(100 * np.abs(err).max()) if k else 0.0,
               "first_off_1pct_hz": float(full[off[0]]) if off.size else None}
        rows.append(row)
        print(f"  {body}: cutoff {c:g} x f_mesh: {row['fixed_interface_modes']} fixed-interface modes, "
              f"{row['modes']} modes in all; below {f_band:.0f} Hz full FE {row['full_below']}, reduced "
              f"{row['reduced_below']}, largest error {row['largest_error_pct']:.3f} %, first more than 1 % off at "
              f"{row['first_off_1pct_hz']} Hz", flush=True)
    print(f"  {body}: {time.process_time() - t0:.0f} s CPU", flush=True)
    return rows


def main() -> None:
    from pathlib import Path

    from flexgear.spec import load_gearbox

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("components", nargs="*", help=f"bodies among {', '.join([*COMPONENTS, 'tied'])}")
    ap.add_argument("--level", default="coarse")
    ap.add_argument("--orders", type=int, nargs="+", default=[0, 2, 4, 6, 8])
    ap.add_argument("--modes", type=int, nargs="+", default=[0, 10, 20, 40])
    ap.add_argument("--kernel-orders", type=int, nargs="*", default=[4, 8, 16, 32])
    ap.add_argument("--gearbox", default=str(Path(__file__).resolve().parents[1] / "model_variants/gearbox.toml"))
    ap.add_argument("--assembly", nargs="?", const="model7", default=None, metavar="VARIANT",
                    help="compare the variant's linearised modes with the full-FE assembly (default model7)")
    ap.add_argument("--f-max", type=float, default=None, help="highest frequency [Hz] (default 3x mesh frequency)")
    ap.add_argument("--band", action="store_true", help="fixed-interface cutoffs against full FE (docstring)")
    ap.add_argument("--cutoff-orders", type=float, nargs="+", default=[3.0, 3.5, 4.0, 5.0])
    ap.add_argument("--band-orders", type=float, default=3.0)
    args = ap.parse_args()
    if set(args.components) - {*COMPONENTS, "tied"}:
        ap.error(f"bodies must be among {[*COMPONENTS, 'tied']}, got {args.components}")
    if args.assembly:
        assembly(args.assembly, args.f_max)
        return
    spec = load_gearbox(args.gearbox)
    if args.band:
        for body in args.components or [*COMPONENTS, "tied"]:
            band(spec, body, args.level, args.cutoff_orders, args.band_orders)
        return
    for component in args.components or list(COMPONENTS[:3]):
        study(spec, component, args.level, sorted(args.orders), sorted(args.modes), args.kernel_orders)


if __name__ == "__main__":
    main()
