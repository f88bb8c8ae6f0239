#!/usr/bin/env python3
"""The solid plate pendulum of decks/superelement/plate_solid_pendulum.dat in Exudyn, fed the
same matrices (issue 38's plate target; docs/superelements.md, "The plate against Exudyn").

    python3 plate_exudyn.py --modes K --h H [--tend 0.3] [--gravity-moment] --out tip.csv

It reads decks/superelement/plate_solid/ (K.mtx, M.mtx by scipy.io.mmread, nodes.csv) into an
exudyn.FEM.FEMinterface (nodes['Position'], massMatrix, stiffnessMatrix as scipy CSR, the
node-wise ux uy uz order of dofs.csv), computes Hurty-Craig-Bampton modes with two rigid
interfaces (HCBstaticModeSelection.RBE2): the hinge edge's 22 nodes (y = 0, both faces; the
first interface, whose rigid motion is the floating frame's and is excluded) and the 2 x 2 x 2
nodes of the far corner (6 static modes), plus K fixed-interface eigenmodes — the basis
mecano-rs builds from the deck's RBE2 1000 and RBE2 2000 with MODES K. Then
ObjectFFRFreducedOrderInterface -> AddObjectFFRFreducedOrder (full inertia coupling, gravity
as LoadMassProportional, the consistent load). Its frame node is at the origin, on the hinge
axis (the x axis): every mode vanishes at the hinge's nodes, so they move with the frame and a
GenericJoint on the frame node (rotation about x free) is the deck's HINGE on the RBE2.
Released at rest, gravity -z, undamped. Integrator: Exudyn's implicit solver in Newmark mode,
beta = 1/4, gamma = 1/2 (the trapezoidal rule: mecano-rs's HHT with alpha = 0), index 3,
full Newton, fixed step H. The tip is a MarkerSuperElementPosition over the corner's 8 nodes
(weights 1/8: the rigid patch's centroid, mecano-rs's node 2); its position is written at
every 1e-3 s: columns t, x, y, z.

Gravity. Exudyn's LoadMassProportional on an ObjectFFRFreducedOrder gives the frame the
moment of the weight about it with the undeformed centre of mass, c0 x R^T m g (as its
Python user-function route, FEM.py UFforceFFRFreducedOrder, writes: Skew(chiU)); the
deformation's first moment C1 q, C1 = Phi_t^T M Psi (its mPhitTPsi), is left out of the
moment (it is in the modal coordinates' load). The potential -g^T(m x0 + R (c0 + C1 q)) gives
the moment (c0 + C1 q) x R^T g. `--gravity-moment` adds the missing (R C1 q) x g as a
LoadTorqueVector on the frame node (a user function of q and R): with it the two codes agree
to their time discretisation (docs/superelements.md, "The plate against Exudyn").

Needs exudyn 1.13.6 and scipy (the Craig-Bampton modes use scipy.sparse.linalg).
"""
import argparse
import json
import os
import sys
import time
import warnings

import numpy as np
import scipy.io
import scipy.sparse
import exudyn as exu
from exudyn.FEM import FEMinterface, ObjectFFRFreducedOrderInterface, HCBstaticModeSelection
from exudyn.itemInterface import (ObjectGround, MarkerBodyRigid, MarkerNodeRigid, ObjectJointGeneric,
                                  MarkerSuperElementPosition, SensorMarker, LoadTorqueVector)

warnings.filterwarnings("ignore", category=DeprecationWarning)
HERE = os.path.dirname(os.path.abspath(__file__))
PLATE = os.path.join(HERE, "..", "..", "decks", "superelement", "plate_solid")
HINGE = list(range(1, 12)) + list(range(78, 89))          # FE nodes (1-based) of RBE2 1000
TIP = [65, 66, 76, 77, 142, 143, 153, 154]                  # FE nodes of RBE2 2000
PERIOD = 1e-3                                               # output sampling (s)


def read_plate(folder=PLATE):
    k = scipy.sparse.csr_matrix(scipy.io.mmread(os.path.join(folder, "K.mtx")))
    m = scipy.sparse.csr_matrix(scipy.io.mmread(os.path.join(folder, "M.mtx")))
    nodes = np.loadtxt(os.path.join(folder, "nodes.csv"), delimiter=",", skiprows=1)
    dofs = np.loadtxt(os.path.join(folder, "dofs.csv"), delimiter=",", skiprows=1, dtype=int)
    # Exudyn's order is node-wise ux uy uz: check dofs.csv says so
    n = len(nodes)
    assert np.array_equal(nodes[:, 0], np.arange(1, n + 1))
    assert np.array_equal(dofs[:, 1], np.repeat(np.arange(1, n + 1), 3))
    assert np.array_equal(dofs[:, 2], np.tile([1, 2, 3], n))
    return k, m, nodes[:, 1:]


def build(mbs, modes, folder=PLATE, gravity_moment=False):
    k, m, xyz = read_plate(folder)
    fem = FEMinterface()
    fem.nodes = {"Position": xyz}
    fem.massMatrix, fem.stiffnessMatrix = m, k
    fem.ComputeHurtyCraigBamptonModes(boundaryNodesList=[[p - 1 for p in HINGE], [p - 1 for p in TIP]],
                                      nEigenModes=modes, useSparseSolver=True,
                                      computationMode=HCBstaticModeSelection.RBE2)
    cms = ObjectFFRFreducedOrderInterface(fem)
    obj = cms.AddObjectFFRFreducedOrder(mbs, positionRef=[0, 0, 0], initialVelocity=[0, 0, 0],
                                        initialAngularVelocity=[0, 0, 0], gravity=[0, 0, -9.81])
    if gravity_moment:
        c1 = np.array(cms.mPhitTPsi)            # 3 x n: the first moment per modal coordinate
        g = np.array([0, 0, -9.81])
        nq, nr = obj["nGenericODE2"], obj["nRigidBody"]

        def moment(mbs_, t, load):
            q = np.array(mbs_.GetNodeOutput(nq, exu.OutputVariableType.Coordinates))
            rot = np.array(mbs_.GetNodeOutput(nr, exu.OutputVariableType.RotationMatrix)).reshape(3, 3)
            return list(np.cross(rot @ (c1 @ q), g))

        mr = mbs.AddMarker(MarkerNodeRigid(nodeNumber=nr))
        mbs.AddLoad(LoadTorqueVector(markerNumber=mr, loadVector=[0, 0, 0], loadVectorUserFunction=moment))
    ground = mbs.AddObject(ObjectGround(referencePosition=[0, 0, 0]))
    mg = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[0, 0, 0]))
    mf = mbs.AddMarker(MarkerNodeRigid(nodeNumber=obj["nRigidBody"]))
    mbs.AddObject(ObjectJointGeneric(markerNumbers=[mg, mf], constrainedAxes=[1, 1, 1, 0, 1, 1]))
    mt = mbs.AddMarker(MarkerSuperElementPosition(bodyNumber=obj["oFFRFreducedOrder"],
                                                  meshNodeNumbers=[p - 1 for p in TIP],
                                                  weightingFactors=[1 / len(TIP)] * len(TIP)))
    sens = mbs.AddSensor(SensorMarker(markerNumber=mt, storeInternal=True,
                                      outputVariableType=exu.OutputVariableType.Position))
    return sens, fem.eigenValues


def run(modes, h, tend=0.3, gravity_moment=False):
    """The tip's path, rows (t, x, y, z) at t = j * PERIOD, and a record of the run."""
    steps = int(round(tend / h))
    if abs(steps * h - tend) > 1e-9 or abs(PERIOD / h - round(PERIOD / h)) > 1e-9:
        raise ValueError(f"h = {h} must divide {PERIOD} and {tend}")
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    sens, eig = build(mbs, modes, gravity_moment=gravity_moment)
    mbs.Assemble()
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.endTime, ti.numberOfSteps = tend, steps
    ti.adaptiveStep = False
    ti.automaticStepSize = False
    ti.verboseMode = 0
    ti.newton.relativeTolerance = 1e-10
    ti.newton.absoluteTolerance = 1e-10
    ti.newton.useModifiedNewton = False
    ga = ti.generalizedAlpha
    ga.useNewmark = True
    ga.newmarkBeta, ga.newmarkGamma = 0.25, 0.5
    ga.useIndex2Constraints = False
    ga.computeInitialAccelerations = True
    s.solution.file.write = False
    s.solution.sensors.writePeriod = h
    s.parallel.numberOfThreads = 1
    s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    cpu0 = time.process_time()
    ok = exu.SolveDynamic(mbs, s)
    cpu = time.process_time() - cpu0
    d = np.array(mbs.GetSensorStoredData(sens))
    j = np.rint(d[:, 0] / PERIOD)
    keep = np.abs(d[:, 0] - j * PERIOD) < 0.25 * h
    d = d[keep]
    d[:, 0] = j[keep] * PERIOD
    _, first = np.unique(np.rint(d[:, 0] / PERIOD), return_index=True)
    d = d[first]
    ok = bool(ok) and abs(mbs.systemData.GetTime() - tend) < 1e-9
    lowest_hz = (np.sqrt(np.abs(eig[:modes])) / (2 * np.pi)).tolist() if modes else []
    return d, dict(code="exudyn", version=exu.__version__, modes=modes, h=h, cpu=round(cpu, 3), ok=ok,
                   gravity_moment=gravity_moment,
                   fixed_interface_hz=[round(f, 3) for f in lowest_hz])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--modes", type=int, default=6)
    ap.add_argument("--h", type=float, default=1e-3)
    ap.add_argument("--tend", type=float, default=0.3)
    ap.add_argument("--gravity-moment", action="store_true",
                    help="add the deformation's moment of the weight about the frame (see above)")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    d, rec = run(a.modes, a.h, a.tend, a.gravity_moment)
    if rec["ok"]:
        np.savetxt(a.out, d, delimiter=",", header="t,x,y,z", comments="", fmt="%.16e")
    print(json.dumps(rec))
    return 0 if rec["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
