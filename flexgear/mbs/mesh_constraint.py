"""The gear contacts' linear mesh kinematics as Exudyn constraints, one per gear pair (flexgear.mbs.contacts).

delta = G (q - q_ref): each contact's deflection coordinate (``aux``) tied to the coordinates of its two gears
(frames, then the flexible gears' modal coordinates) by one ``ObjectConnectorCoordinateVector`` per gear pair.
"""

from __future__ import annotations

import numpy as np

from flexgear.mbs.bodies import Body, zero_user_jacobian

__all__ = ["MeshConstraint", "contact_pairs"]


def contact_pairs(contacts: list) -> list[tuple[tuple[str, str], np.ndarray]]:
    """The gear pairs (``body1``, ``body2`` of each flexgear.mbs.contacts.GearContact) in order of first appearance
    with their contact rows; each pair's rows must be one
    ascending run, pair after pair (their deflection coordinates are then consecutive nodes, as one vector)."""
    pairs = list(dict.fromkeys((c.body1, c.body2) for c in contacts))
    out = [(pair, np.array([i for i, c in enumerate(contacts) if (c.body1, c.body2) == pair])) for pair in pairs]
    order = np.concatenate([rows for _, rows in out])
    if not np.array_equal(order, np.arange(len(contacts))):
        raise ValueError(f"contacts must be grouped by gear pair, got rows {order.tolist()}")
    return out


class MeshConstraint:
    """The contacts' linear kinematics, delta = G (q - q_ref), as one Exudyn constraint per gear pair.

    ``matrix`` G (n_contacts, n_coordinates) acts on the global coordinate vector (frame coordinates
    of every body in order, then the modal coordinates of the flexible ones at ``modal_offsets``).
    Exudyn's ``ObjectConnectorCoordinateVector`` multiplies each scaling matrix by its marker's dense
    identity Jacobian in every Newton iteration, O(rows cols^2) per marker: one constraint over all coordinates
    of model 7 (20 x 162) took half of the run time. Each gear pair's rows therefore get their own
    constraint on that pair's deflection node (``aux_nodes``, one per pair) and the two gears' coordinates
    (empty ``ObjectGenericODE2`` spans over their nodes). With flexible gears, marker 0 holds the deflections and
    the frames (constant, -G_f) and marker 1 only the modal coordinates (G_m, which turn with the gears): model
    7's planet-ring pair costs 2 (14^2 + 51^2) instead of 2 (20^2 + 63^2). ``blocks``: (constraint, rows,
    np.ix_(rows, columns of marker 1)); :meth:`set` writes a new G (and offset) into them.
    """

    def __init__(self, mbs, bodies: list[Body], contacts: list, aux_nodes: list[int],
                 matrix: np.ndarray, q_ref: np.ndarray, modal_offsets: dict[str, int]):
        from exudyn.itemInterface import (
            MarkerNodeCoordinates,
            MarkerObjectODE2Coordinates,
            ObjectConnectorCoordinateVector,
            ObjectGenericODE2,
        )

        index = {b.name: i for i, b in enumerate(bodies)}
        by_name = {b.name: b for b in bodies}
        self.q_ref = q_ref
        self.blocks: list[tuple[int, np.ndarray, tuple]] = []  # (constraint, rows, np.ix_(rows, columns))
        self.frame_blocks: list[tuple[np.ndarray, np.ndarray] | None] = []  # marker 0 frames: (rows, columns)

        def span(name: str, nodes: list[int], n: int) -> int:
            return mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=mbs.AddObject(ObjectGenericODE2(
                name=name, nodeNumbers=nodes, jacobianUserFunction=zero_user_jacobian(n)))))

        for (pair, rows), aux in zip(contact_pairs(contacts), aux_nodes, strict=True):
            label = f"{pair[0]}_{pair[1]}"
            frames = np.concatenate([np.arange(6 * index[n], 6 * index[n] + 6) for n in pair])
            flexible = [by_name[n] for n in pair if by_name[n].flexible]
            # the modal coordinates the contacts sense (a gear's contact node on interface coordinates, else all)
            modal = [modal_offsets[b.name] + b.node_columns(b.contact_nodes) for b in flexible]
            g = matrix[rows]
            if modal:
                modal = np.concatenate(modal)
                marker0 = span(f"mesh_frames_{label}", [aux, *(by_name[n].node for n in pair)], len(rows) + 12)
                nodes = [n for b in flexible for n in b.contact_nodes]
                marker1 = (mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=nodes[0])) if len(nodes) == 1 else
                           span(f"mesh_modes_{label}", nodes, len(modal)))
                scaling0 = np.hstack([np.eye(len(rows)), -g[:, frames]])
                cols, frame_block = modal, (rows, frames)
            else:
                marker0 = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=aux))
                marker1 = span(f"mesh_span_{label}", [by_name[n].node for n in pair], 12)
                scaling0, cols, frame_block = np.eye(len(rows)), frames, None
            block = mbs.AddObject(ObjectConnectorCoordinateVector(
                name=f"mesh_kinematics_{label}", markerNumbers=[marker0, marker1],
                scalingMarker0=scaling0, scalingMarker1=g[:, cols], offset=g @ q_ref))
            self.blocks.append((block, rows, np.ix_(rows, cols)))
            self.frame_blocks.append(frame_block)

    def blocks_with_rows(self, rows: np.ndarray) -> list[int]:
        """Indices of the blocks (gear pairs) that hold any of ``rows``."""
        return [i for i, (_, r, _) in enumerate(self.blocks) if np.isin(r, rows).any()]

    def set(self, mbs, matrix: np.ndarray, offset: np.ndarray | None = None, modal: bool = True) -> None:
        """Write G (and the offset, if given) into the constraints (a pre-step hot path). ``modal`` False: leave the
        flexible gears' modal columns as they are (flexgear.mbs.contact_kinematics writes them)."""
        for (block, rows, sub), frames in zip(self.blocks, self.frame_blocks, strict=True):
            if modal or frames is None:
                mbs.SetObjectParameter(block, "scalingMarker1", matrix[sub])
            if frames is not None:
                mbs.SetObjectParameter(block, "scalingMarker0", np.hstack([np.eye(len(rows)),
                                                                           -matrix[np.ix_(*frames)]]))
            if offset is not None:
                mbs.SetObjectParameter(block, "offset", offset[rows])
