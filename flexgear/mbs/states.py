"""Recorded body states of the study's gearbox, for animation (``flexgear run --states N``).

Per body: the frame's position (3) and rotation matrix (9, row-major) in the ground frame, and for
a flexible body its modal coordinates q (m) and, as an independent check of any reconstruction,
Exudyn's own global position of one mesh node (``SensorSuperElement``, the "probe": the node with
the largest displacement in the first mode). A mesh node at body-frame position X then sits at

    x(t) = p(t) + A(t) (X + Phi_X q(t)),

Phi_X the node's rows of the reduced body's mode matrix (flexgear.fe.cms.ReducedBody.modes).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from flexgear.fe.ring_shaft import TIED_PAIR

if TYPE_CHECKING:
    from flexgear.mbs.gearbox import GearboxModel

__all__ = ["add_state_sensors", "state_table", "state_bodies"]

_MERGED = {"sun": "input_shaft", "ring": "output_shaft"}


def state_bodies(model: GearboxModel) -> dict[str, dict]:
    """Per body: the component geometries it carries (a rigid gear merged with its rigid shaft carries
    both, the parallel-axis pair's rigid wheel and output shaft likewise; the flexible ring and output shaft, tied, the
    tied pair's body; a planetary stage's carrier its merged output shaft's, or none), whether it is flexible, its
    mode count and probe node."""
    out = {}
    planetary = model.design.spec.gears.arrangement == "planetary"
    pair = not model.design.spec.gears.has_ring
    for name, body in model.bodies.items():
        if pair and name.startswith("planet") and not body.flexible and "output_shaft" not in model.bodies:
            geometries = ["planet", "output_shaft"]  # the parallel-axis pair's wheel merged with its rigid shaft
        elif name.startswith("planet"):
            geometries = ["planet"]
        elif name == "carrier" and body.flexible:
            geometries = ["carrier"]
        elif name == "carrier":  # rigid: it carries the output shaft's geometry where merged with it
            geometries = ["output_shaft"] if "output_shaft" not in model.bodies else []
        elif planetary and name == "ring":  # held by the housing: never merged or tied with the output shaft
            geometries = ["ring"]
        elif name in _MERGED and _MERGED[name] not in model.bodies:  # merged rigid, or tied flexible
            geometries = [TIED_PAIR] if body.flexible else [name, _MERGED[name]]
        else:
            geometries = [name]
        entry = {"geometries": geometries, "flexible": bool(body.flexible), "position": list(map(float, body.position))}
        if body.flexible:
            modes = body.reduced.modes
            entry.update(modes=int(modes.shape[1]), probe_node=int(np.argmax(np.linalg.norm(
                modes[:, 0].reshape(-1, 3), axis=1))))
        out[name] = entry
    return out


def add_state_sensors(mbs, model: GearboxModel) -> dict[str, int]:
    """Sensors of every body's frame (position, rotation matrix), modal coordinates and probe node."""
    import exudyn as exu
    from exudyn.itemInterface import SensorNode, SensorSuperElement

    ovt = exu.OutputVariableType
    bodies = state_bodies(model)
    sensors = {}
    for name, body in model.bodies.items():
        sensors[f"{name}/position"] = mbs.AddSensor(SensorNode(nodeNumber=body.node, outputVariableType=ovt.Position,
                                                               storeInternal=True))
        sensors[f"{name}/rotation"] = mbs.AddSensor(SensorNode(nodeNumber=body.node,
                                                               outputVariableType=ovt.RotationMatrix,
                                                               storeInternal=True))
        if body.flexible:
            if getattr(body, "basis", None) is not None:
                raise ValueError(f"state sensors need {name!r} on its modal coordinates (build with superelements)")
            sensors[f"{name}/modal"] = mbs.AddSensor(SensorNode(nodeNumber=body.modal_node,
                                                                outputVariableType=ovt.Coordinates, storeInternal=True))
            if not getattr(body, "superelement", True):  # no FFRF object: no mesh-node sensor
                continue
            sensors[f"{name}/probe"] = mbs.AddSensor(SensorSuperElement(
                bodyNumber=body.obj, meshNodeNumber=bodies[name]["probe_node"], outputVariableType=ovt.Position,
                storeInternal=True))
    return sensors


def state_table(mbs, sensors: dict[str, int], every: int) -> pd.DataFrame:
    """Every ``every``-th recorded step (the first included): ``time_s`` and per body ``{body}_p{x,y,z}_m``,
    ``{body}_a{ij}`` (rotation matrix), ``{body}_q{j}`` (modal coordinates) and ``{body}_probe_{x,y,z}_m``."""
    cols: dict[str, np.ndarray] = {}
    for key, sensor in sensors.items():
        body, what = key.split("/")
        data = np.asarray(mbs.GetSensorStoredData(sensor))[::every]
        cols.setdefault("time_s", data[:, 0])
        values = data[:, 1:]
        if what == "position":
            names = [f"{body}_p{a}_m" for a in "xyz"]
        elif what == "rotation":
            names = [f"{body}_a{i}{j}" for i in range(3) for j in range(3)]
        elif what == "modal":
            names = [f"{body}_q{j}" for j in range(values.shape[1])]
        else:
            names = [f"{body}_probe_{a}_m" for a in "xyz"]
        cols.update(zip(names, values.T, strict=True))
    return pd.DataFrame(cols)
