"""Benchmark: cost of Exudyn's ObjectConnectorCoordinateVector against the columns of its markers.

Run: nice -n 5 python benchmarks/bench_constraint_scaling.py

The gear meshes' linear kinematics (flexgear.mbs.mesh_constraint.MeshConstraint) are one such constraint per
gear pair: 2 rows (helix halves), marker 1 over the two gears' frame (6 + 6) and modal (m + m)
coordinates, marker 0 on the node that holds all contacts' deflections (20 coordinates). This
stand-alone system (10 such blocks on linear springs, 2000 steps) prints Exudyn's ``reactionForces``
timer per Newton iteration for 12 span columns (rigid gears), 24, 36 (12 modes per flexible gear, as
model 7 today) and 72 (30 modes), with marker 0 on one shared 20-coordinate node ("shared", as now)
or on a 2-coordinate node per block ("per pair").
"""

from __future__ import annotations

import io
import re
import sys
import time

import exudyn as exu
import numpy as np
from exudyn.itemInterface import (
    LoadCoordinate,
    MarkerNodeCoordinate,
    MarkerNodeCoordinates,
    MarkerObjectODE2Coordinates,
    NodeGenericODE2,
    ObjectConnectorCoordinateVector,
    ObjectGenericODE2,
)
from speed_common import load_average


def _node(mbs, n: int, mass: float, stiffness: float) -> int:
    node = mbs.AddNode(NodeGenericODE2(numberOfODE2Coordinates=n, referenceCoordinates=[0.0] * n,
                                       initialCoordinates=[0.0] * n, initialCoordinates_t=[0.0] * n))
    mbs.AddObject(ObjectGenericODE2(nodeNumbers=[node], massMatrix=mass * np.eye(n),
                                    stiffnessMatrix=stiffness * np.eye(n)))
    return node


def run(cols: int, shared_aux: bool, blocks: int = 10, steps: int = 2000) -> tuple[float, float, int]:
    """CPU time [s], reactionForces share [%] and Newton iterations of the stand-in system."""
    mbs = exu.SystemContainer().AddSystem()
    nodes = [_node(mbs, cols // 2, 1.0, 1e4) for _ in range(blocks + 1)]
    for n in nodes:
        marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=n, coordinate=0))
        mbs.AddLoad(LoadCoordinate(markerNumber=marker, load=1.0))
    if shared_aux:
        aux = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=_node(mbs, 2 * blocks, 1e-3, 1e3)))
    rng = np.random.default_rng(0)
    for b in range(blocks):
        span = mbs.AddObject(ObjectGenericODE2(nodeNumbers=[nodes[b], nodes[b + 1]]))
        m0 = aux if shared_aux else mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=_node(mbs, 2, 1e-3, 1e3)))
        select = np.eye(2 * blocks)[2 * b:2 * b + 2] if shared_aux else np.eye(2)
        mbs.AddObject(ObjectConnectorCoordinateVector(
            markerNumbers=[m0, mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=span))],
            scalingMarker0=select, scalingMarker1=rng.normal(size=(2, cols)), offset=[0.0, 0.0]))
    mbs.Assemble()
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.endTime, ti.numberOfSteps, ti.verboseMode = steps * 1e-5, steps, 1
    ti.newton.useModifiedNewton = True
    s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    s.solution.file.write = False
    s.displayComputationTime, s.displayStatistics = True, True
    buf, old = io.StringIO(), sys.stdout
    sys.stdout = buf
    c0 = time.process_time()
    try:
        mbs.SolveDynamic(s, solverType=exu.DynamicSolverType.GeneralizedAlpha)
    finally:
        sys.stdout = old
    cpu = time.process_time() - c0
    text = buf.getvalue()
    pct = float(re.search(r"reactionForces\s*=\s*([\d.eE+-]+)%", text).group(1))
    iterations = int(re.search(r"Newton iterations:\s*(\d+)", text).group(1))
    return cpu, pct, iterations


def main() -> None:
    print(load_average())
    for shared in (True, False):
        for cols in (12, 24, 36, 72):
            cpu, pct, it = run(cols, shared)
            label = "shared 20-coordinate node" if shared else "2-coordinate node per pair"
            print(f"marker 0 on {label}, span {cols:3d} columns: reactionForces "
                  f"{1e6 * cpu * pct / 100 / it:7.2f} us per Newton iteration (10 blocks of 2 rows)")


if __name__ == "__main__":
    main()
