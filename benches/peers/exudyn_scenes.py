#!/usr/bin/env python3
"""The scenes of mecano-rs's benchmarks built in Exudyn (benches/peers/README.md).

    python3 exudyn_scenes.py SCENE --h H --n N --out RUN.csv

SCENE is one of pendulum, cantilever, spinup, slider_crank. N is Exudyn's mesh (two-node
geometrically exact beams per bar, per leg, per beam or per rod), H its fixed step. The run
writes RUN.csv, the scene's compared quantities at the sampling instants of the scene (the
same columns as benches/peers/quantities.py gives for mecano-rs), and prints one line of
JSON: code, scene, h, n, cpu (process seconds of the solve), steps, newton, jacobians, ok.

Every scene is the deck's model (same data, loads, joints, start), with Exudyn's own
elements: ObjectBeamGeometricallyExact (3-D, Simo-Reissner, constant strain per element,
Euler-parameter nodes; its beam axis is the node's local z in 1.13.6:
benches/exudyn/README.md) for the spatial scenes, ObjectBeamGeometricallyExact2D (the same
theory in the plane, 3 coordinates per node) for the planar ones. Exudyn's implicit
generalized-alpha, index 3, modified Newton (its defaults), sparse LU, one thread.
"""
import argparse
import json
import math
import sys
import time
import warnings

import numpy as np
import exudyn as exu
from exudyn.itemInterface import (NodeRigidBodyEP, NodeRigidBody2D, NodePointGround,
                                  ObjectGround, ObjectBeamGeometricallyExact,
                                  ObjectBeamGeometricallyExact2D, ObjectMassPoint,
                                  ObjectMassPoint2D, MarkerNodeRigid, MarkerNodePosition,
                                  MarkerBodyRigid, MarkerNodeCoordinate, ObjectJointGeneric,
                                  ObjectConnectorCoordinate, LoadForceVector,
                                  LoadTorqueVector, SensorNode)
from exudyn.rigidBodyUtilities import RotationMatrix2EulerParameters

warnings.filterwarnings("ignore", category=DeprecationWarning)
POS = exu.OutputVariableType.Position
VEL = exu.OutputVariableType.Velocity
ROT = exu.OutputVariableType.Rotation

# Sampling period (s), end time (s) and the columns of each scene: the compared quantities.
SCENES = {
    "pendulum": dict(period=1e-3, tend=1.5,
                     columns=["x12", "y12", "z12", "x23", "y23", "z23"]),
    "cantilever": dict(period=0.1, tend=30.0,
                       columns=["x2", "y2", "z2", "x3", "y3", "z3"]),
    "spinup": dict(period=0.1, tend=20.0, columns=["v3"]),
    "slider_crank": dict(period=1e-4, tend=0.06, columns=["w"]),
}


def frame_z_along(d, y_hint):
    """Columns (x, y, z) of a right-handed frame with z along d and y in the plane of y_hint."""
    z = np.asarray(d, float) / np.linalg.norm(d)
    y = np.asarray(y_hint, float) - np.dot(y_hint, z) * z
    y /= np.linalg.norm(y)
    return np.column_stack([np.cross(y, z), y, z])


def beam_section(EA, GA2, GA3, GJ, EI2, EI3, rhoA, rhoJ, rhoI2, rhoI3):
    """Exudyn's section: local x, y the section's axes 2, 3, local z the beam axis."""
    sec = exu.BeamSection()
    sec.stiffnessMatrix = np.diag([GA2, GA3, EA, EI2, EI3, GJ])
    sec.inertia = np.diag([rhoI2, rhoI3, rhoJ])
    sec.massPerLength = rhoA
    return sec


def add_bar(mbs, p0, p1, n, R, sec):
    """n beams from p0 to p1 on n + 1 Euler-parameter nodes of frame R; returns the nodes."""
    ep = list(RotationMatrix2EulerParameters(R))
    nodes = [mbs.AddNode(NodeRigidBodyEP(referenceCoordinates=list(p0 + (p1 - p0) * i / n) + ep))
             for i in range(n + 1)]
    le = np.linalg.norm(p1 - p0) / n
    for a, b in zip(nodes[:-1], nodes[1:]):
        mbs.AddObject(ObjectBeamGeometricallyExact(nodeNumbers=[a, b], length=le, sectionData=sec))
    return nodes


def weld(mbs, na, Ra, nb, Rb, axes=(1, 1, 1, 1, 1, 1), frame=None):
    """A generic joint between two rigid nodes whose marker frames coincide at t = 0
    (frame: the joint's global frame at t = 0, default the identity)."""
    F = np.eye(3) if frame is None else frame
    ma = mbs.AddMarker(MarkerNodeRigid(nodeNumber=na, localHT=exu.HT(rotation=Ra.T @ F, translation=[0, 0, 0])))
    mb = mbs.AddMarker(MarkerNodeRigid(nodeNumber=nb, localHT=exu.HT(rotation=Rb.T @ F, translation=[0, 0, 0])))
    return mbs.AddObject(ObjectJointGeneric(markerNumbers=[ma, mb], constrainedAxes=list(axes)))


# ----------------------------------------------------------------- the seed's pendulum
def pendulum(mbs, n):
    """decks/pendulum.dat (shared/design/scenario.md): n beams per bar; as
    benches/exudyn/pendulum_exudyn.py, which it generalises to any n (same joints, gravity
    as consistent nodal loads, torque and floor as user-function loads, the floor's active
    set switched at step ends with a repeated step, Exudyn's way)."""
    E, nu, rho, A, I, J, k = 2.1e11, 0.3, 7800.0, 9e-4, 8.3e-8, 4.15e-8, 5.0 / 6.0
    G = E / (2 * (1 + nu))
    sec = beam_section(E * A, k * G * A, k * G * A, G * J, E * I, E * I, rho * A, rho * 2 * I, rho * I, rho * I)
    c30, s30 = math.cos(math.pi / 6), math.sin(math.pi / 6)
    d2 = np.array([c30, 0, s30])
    R1 = frame_z_along([1, 0, 0], [0, 0, 1])
    R2 = frame_z_along(d2, [0, 1, 0])
    bar1 = add_bar(mbs, np.zeros(3), np.array([1.0, 0, 0]), n, R1, sec)
    bar2 = add_bar(mbs, np.array([1.0, 0, 0]), np.array([1.0, 0, 0]) + d2, n, R2, sec)
    for tip in (bar1[-1], bar2[-1]):
        mbs.AddObject(ObjectMassPoint(mass=1.0, nodeNumber=tip))
    grav = np.array([0, -9.81, 0])
    le = 1.0 / n
    mpos = {}
    for bar in (bar1, bar2):
        for i, nd in enumerate(bar):
            m = rho * A * le * (0.5 if i in (0, n) else 1.0) + (1.0 if i == n else 0.0)
            mpos[nd] = mbs.AddMarker(MarkerNodePosition(nodeNumber=nd))
            mbs.AddLoad(LoadForceVector(markerNumber=mpos[nd], loadVector=list(m * grav)))
    ground = mbs.AddObject(ObjectGround())
    mg = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[0, 0, 0]))
    m2 = mbs.AddMarker(MarkerNodeRigid(nodeNumber=bar1[0], localHT=exu.HT(rotation=R1.T, translation=[0, 0, 0])))
    mbs.AddObject(ObjectJointGeneric(markerNumbers=[mg, m2], constrainedAxes=[1, 1, 1, 1, 1, 0]))
    # universal joint: marker 0's y axis = global Z (fixed in bar 1), marker 1's z axis =
    # global Y (fixed in bar 2): (A0 e_y).(A1 e_z) = 0
    A0 = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])
    A1 = np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]])
    ma = mbs.AddMarker(MarkerNodeRigid(nodeNumber=bar1[-1], localHT=exu.HT(rotation=R1.T @ A0, translation=[0, 0, 0])))
    mb = mbs.AddMarker(MarkerNodeRigid(nodeNumber=bar2[0], localHT=exu.HT(rotation=R2.T @ A1, translation=[0, 0, 0])))
    mbs.AddObject(ObjectJointGeneric(markerNumbers=[ma, mb], constrainedAxes=[1, 1, 1, 1, 0, 0]))

    def tri(t):
        return 0.0 if t <= 0 or t >= 0.02 else (t / 0.01 if t <= 0.01 else (0.02 - t) / 0.01)

    mt = mbs.AddMarker(MarkerNodeRigid(nodeNumber=bar1[0]))
    mbs.AddLoad(LoadTorqueVector(markerNumber=mt, loadVector=[0, 0, 0],
                                 loadVectorUserFunction=lambda mbs_, t, load: [0, 0, -1000.0 * tri(t)]))
    tip = bar2[-1]
    flag = {"on": False}

    def contact(mbs_, t, load):
        if not flag["on"]:
            return [0, 0, 0]
        gap = mbs_.GetNodeOutput(tip, POS)[1] + 1.8
        return [0, -1e7 * gap - 1e3 * mbs_.GetNodeOutput(tip, VEL)[1], 0]

    def post_newton(mbs_, t):
        # the deck's CAME ... CLIP OFF: the Kelvin-Voigt force acts, tensile part included,
        # while the tip is below the floor (a clipped law, F > 0 also required, is CLIP ON's)
        on = mbs_.GetNodeOutput(tip, POS)[1] + 1.8 < 0
        if on != flag["on"]:
            flag["on"] = on
            return [2.0, -1.0]
        return [0.0, -1.0]

    mbs.SetPostNewtonUserFunction(post_newton)
    mbs.AddLoad(LoadForceVector(markerNumber=mpos[tip], loadVector=[0, 0, 0], loadVectorUserFunction=contact))
    sens = [mbs.AddSensor(SensorNode(nodeNumber=nd, storeInternal=True, outputVariableType=POS))
            for nd in (bar1[-1], tip)]

    def columns(mbs_):
        return join(stored(mbs_, s) for s in sens)

    # HHT alpha = -0.1 through Exudyn's generalized-alpha (alpha_m = 0), the seed's scheme.
    # Newton's absolute tolerance (N) grows with the mesh as the residual's round-off floor
    # does (the axial stiffness EA / le): 1e-5 at 10 beams per bar, Exudyn's pendulum's
    # (benches/exudyn/README.md); at 40 beams 1e-5 is below the floor and step 1 fails.
    return columns, dict(hht=-0.1, abstol=1e-6 * n)


# --------------------------------------------------------------- right-angle cantilever
def cantilever(mbs, n):
    """decks/benchmarks/right_angle_cantilever.dat: two legs of 10 m, n beams each, welded
    at the elbow (two nodes of different frames held by a generic joint), force along Z at
    the elbow 50 f(t), f the triangle 0 -> 1 at 1 s -> 0 at 2 s."""
    sec = beam_section(1e6, 1e6, 1e6, 1e3, 1e3, 1e3, 1.0, 20.0, 10.0, 10.0)
    R1 = frame_z_along([1, 0, 0], [0, 1, 0])
    R2 = frame_z_along([0, 1, 0], [-1, 0, 0])
    leg1 = add_bar(mbs, np.zeros(3), np.array([10.0, 0, 0]), n, R1, sec)
    leg2 = add_bar(mbs, np.array([10.0, 0, 0]), np.array([10.0, 10.0, 0]), n, R2, sec)
    ground = mbs.AddObject(ObjectGround())
    mg = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[0, 0, 0]))
    m1 = mbs.AddMarker(MarkerNodeRigid(nodeNumber=leg1[0], localHT=exu.HT(rotation=R1.T, translation=[0, 0, 0])))
    mbs.AddObject(ObjectJointGeneric(markerNumbers=[mg, m1], constrainedAxes=[1] * 6))
    weld(mbs, leg1[-1], R1, leg2[0], R2)

    def f(t):
        return t if t <= 1 else (2 - t if t <= 2 else 0.0)

    me = mbs.AddMarker(MarkerNodePosition(nodeNumber=leg1[-1]))
    mbs.AddLoad(LoadForceVector(markerNumber=me, loadVector=[0, 0, 0],
                                loadVectorUserFunction=lambda mbs_, t, load: [0, 0, 50.0 * f(t)]))
    sens = [mbs.AddSensor(SensorNode(nodeNumber=nd, storeInternal=True, outputVariableType=POS))
            for nd in (leg1[-1], leg2[-1])]
    return (lambda mbs_: join(stored(mbs_, s) for s in sens)), dict(rho=1.0, abstol=1e-6)


# ------------------------------------------------------------------- Kane's spin-up beam
def spinup_angle(t, ws=4.0, T=15.0):
    if t <= T:
        return ws / T * (t * t / 2 + (T / (2 * math.pi)) ** 2 * (math.cos(2 * math.pi * t / T) - 1))
    return ws * (t - T / 2)


def spinup(mbs, n):
    """decks/benchmarks/spinup.dat (omega_s = 4 rad/s): a 10 m beam of n planar
    geometrically exact elements clamped to a hub whose angle is driven (coordinate
    constraints: the hub node's x, y held, its rotation coordinate = theta(t))."""
    L = 10.0
    nodes = [mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[L * i / n, 0, 0])) for i in range(n + 1)]
    for a, b in zip(nodes[:-1], nodes[1:]):
        mbs.AddObject(ObjectBeamGeometricallyExact2D(nodeNumbers=[a, b], physicsLength=L / n,
                                                     physicsMassPerLength=1.2, physicsCrossSectionInertia=6e-4,
                                                     physicsBendingStiffness=1.4e4, physicsAxialStiffness=2.8e7,
                                                     physicsShearStiffness=1e7))
    g = mbs.AddNode(NodePointGround(referenceCoordinates=[0, 0, 0]))
    mg = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=g, coordinate=0))
    for c in (0, 1):
        mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[mg, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=c))]))
    mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[mg, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=2))],
                                            offsetUserFunction=lambda mbs_, t, item, off: spinup_angle(t)))
    s = mbs.AddSensor(SensorNode(nodeNumber=nodes[-1], storeInternal=True, outputVariableType=POS))

    def columns(mbs_):
        d = stored(mbs_, s)
        th = np.array([spinup_angle(t) for t in d[:, 0]])
        return np.column_stack([d[:, 0], -d[:, 1] * np.sin(th) + d[:, 2] * np.cos(th)])

    return columns, dict(rho=0.9, abstol=1e-5)


# -------------------------------------------------------------- flexible slider-crank
def slider_crank(mbs, n):
    """decks/benchmarks/slider_crank_flexible.dat: the crank pin driven on its circle
    (r = 0.15 m, 150 rad/s: coordinate constraints on the rod's first node, its rotation
    free: a pin), the rod of n planar geometrically exact elements (d = 6 mm steel), its end
    node held on the X axis with the slider's mass; every node starts with the rigid
    mechanism's velocity. Output: the mid-span deflection on the normal to the chord."""
    r, l, w, d, rho, E, nu = 0.15, 0.3, 150.0, 6e-3, 7870.0, 200e9, 0.3
    A, I = math.pi * d * d / 4, math.pi * d ** 4 / 64
    G = E / (2 * (1 + nu))
    nodes = []
    for i in range(n + 1):
        x = r + l * i / n
        s = l * i / n
        # rigid start: rod turns at -r w / l about the crank pin, which moves at (0, r w)
        wr = -r * w / l
        nodes.append(mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[x, 0, 0],
                                                 initialVelocities=[0, r * w + wr * s, wr])))
    for a, b in zip(nodes[:-1], nodes[1:]):
        mbs.AddObject(ObjectBeamGeometricallyExact2D(nodeNumbers=[a, b], physicsLength=l / n,
                                                     physicsMassPerLength=rho * A, physicsCrossSectionInertia=rho * I,
                                                     physicsBendingStiffness=E * I, physicsAxialStiffness=E * A,
                                                     physicsShearStiffness=5.0 / 6.0 * G * A))
    mbs.AddObject(ObjectMassPoint2D(physicsMass=0.5 * rho * A * l, nodeNumber=nodes[-1]))
    g = mbs.AddNode(NodePointGround(referenceCoordinates=[0, 0, 0]))
    mg = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=g, coordinate=0))
    mk = lambda nd, c: mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nd, coordinate=c))
    mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[mg, mk(nodes[0], 0)],
                                            offsetUserFunction=lambda mbs_, t, item, off: r * (math.cos(w * t) - 1)))
    mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[mg, mk(nodes[0], 1)],
                                            offsetUserFunction=lambda mbs_, t, item, off: r * math.sin(w * t)))
    mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[mg, mk(nodes[-1], 1)]))
    sens = [mbs.AddSensor(SensorNode(nodeNumber=nodes[i], storeInternal=True, outputVariableType=POS))
            for i in (0, n // 2, n)]

    def columns(mbs_):
        a, m, b = (stored(mbs_, s) for s in sens)
        chord = b[:, 1:3] - a[:, 1:3]
        e1 = chord / np.linalg.norm(chord, axis=1)[:, None]
        nrm = np.column_stack([-e1[:, 1], e1[:, 0]])
        wv = np.sum((m[:, 1:3] - 0.5 * (a[:, 1:3] + b[:, 1:3])) * nrm, axis=1)
        return np.column_stack([a[:, 0], wv])

    # Newton's absolute tolerance grows with the mesh past 32 beams, as the residual's
    # round-off floor does (EA / le); at 128 beams 1e-6 is below it and step 1 fails
    return columns, dict(rho=0.9, abstol=1e-6 * max(1.0, n / 32))


BUILDERS = dict(pendulum=pendulum, cantilever=cantilever, spinup=spinup, slider_crank=slider_crank)
_SAMPLE = {}


def stored(mbs, sensor):
    """A sensor's rows (t, values...) at the instants k * period, one per instant."""
    d = np.array(mbs.GetSensorStoredData(sensor))
    period, h = _SAMPLE["period"], _SAMPLE["h"]
    k = np.rint(d[:, 0] / period)
    keep = np.abs(d[:, 0] - k * period) < 0.25 * h
    d = d[keep]
    d[:, 0] = k[keep] * period
    _, first = np.unique(np.rint(d[:, 0] / period), return_index=True)
    return d[first]


def join(parts):
    """Rows (t, a...), (t, b...) of the same instants -> (t, a..., b...)."""
    parts = list(parts)
    n = min(len(p) for p in parts)
    return np.hstack([parts[0][:n]] + [p[:n, 1:] for p in parts[1:]])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", choices=sorted(SCENES))
    ap.add_argument("--h", type=float, required=True)
    ap.add_argument("--n", type=int, required=True)
    ap.add_argument("--tend", type=float, help="end time (default: the scene's)")
    ap.add_argument("--abstol", type=float, help="Newton's absolute tolerance (default: the scene's)")
    ap.add_argument("--reltol", type=float, default=1e-8,
                    help="Newton's relative tolerance (default 1e-8, the bench's)")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    sc = SCENES[a.scene]
    tend = a.tend or sc["tend"]
    steps = int(round(tend / a.h))
    per = sc["period"] / a.h
    if abs(per - round(per)) > 1e-9 or abs(steps * a.h - tend) > 1e-9 * tend:
        sys.exit(f"h = {a.h} must divide the sampling period {sc['period']} and the end time {tend}")
    _SAMPLE.update(period=sc["period"], h=a.h)

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    columns, opt = BUILDERS[a.scene](mbs, a.n)
    mbs.Assemble()
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.endTime, ti.numberOfSteps = tend, steps
    ti.adaptiveStep = False
    ti.automaticStepSize = False
    ti.verboseMode = 0
    ti.newton.relativeTolerance = a.reltol
    ti.newton.absoluteTolerance = a.abstol or opt["abstol"]
    ti.newton.useModifiedNewton = True
    ti.computeLoadsJacobian = 2 if a.scene == "pendulum" else 0
    ga = ti.generalizedAlpha
    ga.useNewmark = False
    ga.useIndex2Constraints = False
    ga.computeInitialAccelerations = True
    ga.spectralRadius = opt.get("rho", 0.9)
    s.solution.file.write = False
    s.solution.sensors.writePeriod = sc["period"]
    s.parallel.numberOfThreads = 1
    s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    solver = exu.MainSolverImplicitSecondOrder()
    cpu0 = time.process_time()
    ok = solver.InitializeSolver(mbs, s)
    if "hht" in opt:      # HHT through generalized-alpha with alpha_m = 0 (benches/exudyn/README.md)
        af = -opt["hht"]
        solver.alphaM, solver.alphaF = 0.0, af
        solver.newmarkGamma = 0.5 + af
        solver.newmarkBeta = 0.25 * (1 + af) ** 2
        solver.factJacAlgorithmic = 1.0 - af
    try:
        ok = bool(ok and solver.SolveSteps(mbs, s))
    except Exception as e:        # Newton failure in a fixed-step run
        print(f"exudyn: {e}", file=sys.stderr)
        ok = False
    solver.FinalizeSolver(mbs, s)
    cpu = time.process_time() - cpu0
    t_reached = mbs.systemData.GetTime()
    ok = ok and abs(t_reached - tend) < 1e-9 * max(1.0, tend)
    data = columns(mbs)
    if ok:
        np.savetxt(a.out, data, delimiter=",", header="t," + ",".join(sc["columns"]), comments="", fmt="%.16e")
    print(json.dumps(dict(code="exudyn", version=exu.__version__, scene=a.scene, h=a.h, n=a.n, cpu=round(cpu, 4),
                          steps=solver.it.currentStepIndex - 1, newton=solver.it.newtonStepsCount,
                          jacobians=solver.it.newtonJacobiCount, ok=ok, t_reached=t_reached)))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
