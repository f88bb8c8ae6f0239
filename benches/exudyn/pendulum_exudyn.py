#!/usr/bin/env python3
"""The reference scene of mecano-rs (decks/pendulum.dat, shared/design/scenario.md) in Exudyn.

Spatial double pendulum of two flexible steel bars (10 geometrically exact beam elements
each), a hinge at the origin about global Z, a universal joint between the bars, 1 kg point
masses at the two tips, gravity, a triangular torque pulse on node 2 and a penalty floor
contact on node 23.  Integrated with Exudyn's generalized-alpha solver set to the HHT member
(alpha_m = 0, alpha_f = 0.1, i.e. HHT alpha = -0.1, rho_inf = 0.8182) at a fixed step.

Usage:
    python3 pendulum_exudyn.py --h 1e-4 --tend 2.0 --out /tmp/exudyn_runs/h1e-4.csv

Writes one CSV with columns t,x12,y12,z12,x23,y23,z23 (global positions of nodes 12 and 23,
metres), sampled at t = k*1e-3 s, and prints CPU seconds (time.process_time of the solve),
the number of steps, Newton iterations and Jacobian evaluations, and a few checks of the scene.

Node numbers below are the deck's (1..23); Exudyn's own node indices are mapped in `node`.
See README.md in this directory for the modelling choices and their caveats.
"""
import argparse
import sys
import time
import warnings

import numpy as np
import exudyn as exu
from exudyn.itemInterface import (NodeRigidBodyEP, ObjectGround, ObjectBeamGeometricallyExact,
                                  ObjectMassPoint, MarkerNodeRigid, MarkerNodePosition,
                                  MarkerBodyRigid, ObjectJointGeneric, LoadForceVector,
                                  LoadTorqueVector, SensorNode)
from exudyn.rigidBodyUtilities import RotationMatrix2EulerParameters

warnings.filterwarnings("ignore", category=DeprecationWarning)

# ---------------------------------------------------------------- data (decks/pendulum.dat)
E = 2.1e11                 # N/m^2
NU = 0.3
G = E / (2.0 * (1.0 + NU))  # = E/2.6
RHO = 7800.0               # kg/m^3
A = 9e-4                   # m^2
I2 = I3 = 8.3e-8           # m^4, bending
J = 4.15e-8                # m^4, torsion constant
K_SHEAR = 5.0 / 6.0
N_EL = 10                  # elements per bar
L_BAR = 1.0
M_TIP = 1.0                # kg at nodes 12 and 23
GRAV = np.array([0.0, -9.81, 0.0])
M_PEAK = -1000.0           # N m about Z at node 2, times the triangle f(t)
Y_FLOOR = -1.8
K_CONT = 1e7               # N/m
C_CONT = 1e3               # N s/m
HHT_ALPHA = -0.1

C30, S30 = np.cos(np.pi / 6), np.sin(np.pi / 6)
D2 = np.array([C30, 0.0, S30])           # direction of bar 2


def triangle(t):
    """Function 1 of the deck: 0 at t=0, 1 at 0.01 s, 0 at 0.02 s and after."""
    if t <= 0.0 or t >= 0.02:
        return 0.0
    return t / 0.01 if t <= 0.01 else (0.02 - t) / 0.01


def build(mbs, contact_mode="switch"):
    """Adds the scene to mbs; returns a dict with the Exudyn indices of interest."""
    # Exudyn 1.13.6's ObjectBeamGeometricallyExact takes the beam axis along the node's
    # *local z* axis (reference relative motion h0 = [0,0,L, 0,0,0]) and applies the six
    # diagonal stiffness entries to the local strains (x, y, z, kx, ky, kz) in that order
    # (checked with static cantilever tests, see README).  So: node frames have local z along
    # the bar, and the section is [kGA, kGA, EA, EI, EI, GJ], inertia rho*[I, I, I2+I3].
    sec = exu.BeamSection()
    sec.stiffnessMatrix = np.diag([K_SHEAR * G * A, K_SHEAR * G * A, E * A,
                                   E * I2, E * I3, G * J])
    sec.inertia = RHO * np.diag([I2, I3, I2 + I3])
    sec.massPerLength = RHO * A

    # node frames: columns = local x, y, z (z along the bar)
    R1 = np.array([[0.0, 0.0, 1.0],
                   [1.0, 0.0, 0.0],
                   [0.0, 1.0, 0.0]])          # [Y, Z, X]
    Ry = np.array([[C30, 0.0, -S30],
                   [0.0, 1.0, 0.0],
                   [S30, 0.0, C30]])          # rotation about Y taking X to d
    R2 = Ry @ R1                              # [Y, (-sin30,0,cos30), d]
    ep1 = list(RotationMatrix2EulerParameters(R1))
    ep2 = list(RotationMatrix2EulerParameters(R2))

    node = {}
    le = L_BAR / N_EL
    for i in range(2, 13):                    # bar 1: nodes 2..12
        p = np.array([le * (i - 2), 0.0, 0.0])
        node[i] = mbs.AddNode(NodeRigidBodyEP(referenceCoordinates=list(p) + ep1))
    for i in range(13, 24):                   # bar 2: nodes 13..23
        p = np.array([1.0, 0.0, 0.0]) + le * (i - 13) * D2
        node[i] = mbs.AddNode(NodeRigidBodyEP(referenceCoordinates=list(p) + ep2))

    for a in list(range(2, 12)) + list(range(13, 23)):
        mbs.AddObject(ObjectBeamGeometricallyExact(nodeNumbers=[node[a], node[a + 1]],
                                                   length=le, sectionData=sec))

    # point masses (translational only) on the tip nodes
    for i in (12, 23):
        mbs.AddObject(ObjectMassPoint(mass=M_TIP, nodeNumber=node[i]))

    # gravity: consistent nodal loads of the linear interpolation (rho A le g / 2 per element
    # end) plus the point masses
    mnode = {i: 0.0 for i in node}
    for a in list(range(2, 12)) + list(range(13, 23)):
        mnode[a] += 0.5 * RHO * A * le
        mnode[a + 1] += 0.5 * RHO * A * le
    mnode[12] += M_TIP
    mnode[23] += M_TIP
    mpos = {i: mbs.AddMarker(MarkerNodePosition(nodeNumber=node[i])) for i in node}
    for i in node:
        mbs.AddLoad(LoadForceVector(markerNumber=mpos[i], loadVector=list(mnode[i] * GRAV)))

    # node 1 = ground
    ground = mbs.AddObject(ObjectGround())
    m_ground = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0]))

    # element 1, HINGE 1 2 AXIS 0 0 1: marker frame on node 2 = global frame at t=0; the
    # generic joint locks the 3 translations and the rotations about x and y of the ground
    # frame, leaving the rotation about global Z free.
    m2 = mbs.AddMarker(MarkerNodeRigid(nodeNumber=node[2],
                                       localHT=exu.HT(rotation=R1.T, translation=[0.0, 0.0, 0.0])))
    mbs.AddObject(ObjectJointGeneric(markerNumbers=[m_ground, m2],
                                     constrainedAxes=[1, 1, 1, 1, 1, 0]))

    # element 12, UJOINT 12 13 AXIS1 0 0 1 AXIS2 0 1 0: Exudyn's generic joint with
    # constrainedAxes [1,1,1,1,0,0] is a universal joint: positions coincide (global
    # equations) and the one rotation equation is  (A0 e_y) . (A1 e_z) = 0, with the y axis of
    # marker 0's frame and the z axis of marker 1's frame as the two cross axes.  Marker 0 (on
    # node 12, bar 1) gets frame [X, Z, -Y] at t=0 (its y = axis 1 = global Z); marker 1 (on
    # node 13, bar 2) gets [X, -Z, Y] at t=0 (its z = axis 2 = global Y = Z x d / |Z x d|).
    A0 = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])   # cols X, Z, -Y
    A1 = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])   # cols X, -Z, Y
    m12 = mbs.AddMarker(MarkerNodeRigid(nodeNumber=node[12],
                                        localHT=exu.HT(rotation=R1.T @ A0, translation=[0.0, 0.0, 0.0])))
    m13 = mbs.AddMarker(MarkerNodeRigid(nodeNumber=node[13],
                                        localHT=exu.HT(rotation=R2.T @ A1, translation=[0.0, 0.0, 0.0])))
    mbs.AddObject(ObjectJointGeneric(markerNumbers=[m12, m13],
                                     constrainedAxes=[1, 1, 1, 1, 0, 0]))

    # torque on node 2 about global Z: -1000 N m x triangle(t)
    m2t = mbs.AddMarker(MarkerNodeRigid(nodeNumber=node[2]))

    def torque(mbs_, t, load):
        return [0.0, 0.0, M_PEAK * triangle(t)]

    mbs.AddLoad(LoadTorqueVector(markerNumber=m2t, loadVector=[0.0, 0.0, 0.0],
                                 loadVectorUserFunction=torque))

    # element 23, CAME ... CLIP OFF: floor y = -1.8, point follower at node 23, penalty with
    # dashpot, F_y = -k g - c g' while g = y23 + 1.8 < 0 (the tensile part of the dashpot's
    # force included: the deck's CLIP OFF; a clipped law, F_y = max(0, ...), is CLIP ON's),
    # no friction; a user-function load.
    #   contact="implicit": the law above evaluated at every Newton iterate (as mecano-rs);
    #     Newton can cycle between the branches at an impact step (it does at h = 1e-3).
    #   contact="switch" (default): Exudyn's own way for such laws: the active flag is frozen
    #     during Newton (F = -k g - c g' if active, 0 if not) and re-decided from the converged
    #     state after each step (post-Newton user function); if it changed, Exudyn repeats the
    #     step from its start with the new flag ("discontinuous iteration", at most 5).  When
    #     the repeat converges to a consistent flag the result is the same solution as the
    #     implicit law; otherwise the last repeat is kept.
    n23 = node[23]
    POS = exu.OutputVariableType.Position
    VEL = exu.OutputVariableType.Velocity
    flag = {"active": False, "switches": 0}

    def law(mbs_):
        gap = mbs_.GetNodeOutput(n23, POS)[1] - Y_FLOOR
        if gap >= 0.0:
            return gap, 0.0
        return gap, -K_CONT * gap - C_CONT * mbs_.GetNodeOutput(n23, VEL)[1]

    if contact_mode == "implicit":
        def contact(mbs_, t, load):
            gap, f = law(mbs_)
            return [0.0, f, 0.0]
    else:
        def contact(mbs_, t, load):
            if not flag["active"]:
                return [0.0, 0.0, 0.0]
            gap = mbs_.GetNodeOutput(n23, POS)[1] - Y_FLOOR
            return [0.0, -K_CONT * gap - C_CONT * mbs_.GetNodeOutput(n23, VEL)[1], 0.0]

        def post_newton(mbs_, t):
            gap, f = law(mbs_)
            new = gap < 0.0
            if new != flag["active"]:
                flag["active"] = new
                flag["switches"] += 1
                return [2.0, -1.0]      # > discontinuous.iterationTolerance (1): repeat the step
            return [0.0, -1.0]

        mbs.SetPostNewtonUserFunction(post_newton)

    mbs.AddLoad(LoadForceVector(markerNumber=mpos[23], loadVector=[0.0, 0.0, 0.0],
                                loadVectorUserFunction=contact))

    # sensors: positions of nodes 12 and 23, kept in memory
    sens = {i: mbs.AddSensor(SensorNode(nodeNumber=node[i], storeInternal=True,
                                        outputVariableType=exu.OutputVariableType.Position))
            for i in (2, 12, 13, 23)}
    return dict(node=node, sens=sens, flag=flag)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--h", type=float, default=1e-4, help="time step, s (must divide 1e-3)")
    ap.add_argument("--tend", type=float, default=2.0, help="end time, s")
    ap.add_argument("--out", default="pendulum_exudyn.csv", help="output CSV path")
    ap.add_argument("--reltol", type=float, default=1e-8, help="Newton relative tolerance (Exudyn default 1e-8)")
    ap.add_argument("--abstol", type=float, default=1e-5, help="Newton absolute tolerance on the residual norm (Exudyn default 1e-10 is below the round-off floor of this model, ~2e-6)")
    ap.add_argument("--full-newton", action="store_true", help="Jacobian at every iteration (default: Exudyn's modified Newton)")
    ap.add_argument("--dense", action="store_true", help="Exudyn's dense LU (default here: EigenSparse, ~2x faster on this model)")
    ap.add_argument("--contact", choices=["switch", "implicit"], default="switch",
                    help="contact active-set handling (see build()); default: switch")
    ap.add_argument("--verbose", type=int, default=0)
    args = ap.parse_args()

    period = 1e-3
    n_steps = int(round(args.tend / args.h))
    per = period / args.h
    if abs(per - round(per)) > 1e-9 or abs(n_steps * args.h - args.tend) > 1e-12 * n_steps:
        sys.exit("h must divide 1e-3 s and the end time")

    cpu0 = time.process_time()
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    ids = build(mbs, args.contact)
    mbs.Assemble()
    cpu_build = time.process_time() - cpu0

    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.startTime = 0.0
    ti.endTime = args.tend
    ti.numberOfSteps = n_steps
    ti.adaptiveStep = False              # fixed steps, no step-size control
    ti.automaticStepSize = False
    ti.verboseMode = args.verbose
    ti.computeLoadsJacobian = 2          # numerical Jacobian of the contact load (positions + velocities)
    ti.newton.relativeTolerance = args.reltol
    ti.newton.absoluteTolerance = args.abstol
    ti.newton.useModifiedNewton = not args.full_newton
    ga = ti.generalizedAlpha
    ga.useNewmark = False
    ga.useIndex2Constraints = False
    ga.computeInitialAccelerations = True
    rho_inf = (1.0 + HHT_ALPHA) / (1.0 - HHT_ALPHA)
    ga.spectralRadius = rho_inf          # replaced below by the HHT member
    s.solution.file.write = False
    s.solution.sensors.writePeriod = period
    s.parallel.numberOfThreads = 1
    s.displayComputationTime = bool(args.verbose)
    if not args.dense:
        s.linearSolver.solverType = exu.LinearSolverType.EigenSparse

    # generalized-alpha (Arnold-Bruls form, as Exudyn implements it) with alpha_m = 0 is HHT:
    # alpha_f = -alpha, gamma = 1/2 - alpha, beta = (1 - alpha)^2 / 4.  Exudyn's settings only
    # offer the Chung-Hulbert member for a spectral radius, so the parameters are set on the
    # solver object after its initialisation (which would otherwise overwrite them).
    alpha_f = -HHT_ALPHA
    alpha_m = 0.0
    gamma = 0.5 + alpha_f - alpha_m
    beta = 0.25 * (gamma + 0.5) ** 2

    solver = exu.MainSolverImplicitSecondOrder()
    cpu1 = time.process_time()
    ok = solver.InitializeSolver(mbs, s)
    solver.alphaM = alpha_m
    solver.alphaF = alpha_f
    solver.newmarkGamma = gamma
    solver.newmarkBeta = beta
    solver.factJacAlgorithmic = (1.0 - alpha_f) / (1.0 - alpha_m)
    success = solver.SolveSteps(mbs, s) if ok else False
    solver.FinalizeSolver(mbs, s)
    cpu_solve = time.process_time() - cpu1
    it = solver.it
    steps = it.currentStepIndex - 1      # the index is one past the last step taken

    # sensor histories (t, x, y, z); keep the samples at t = k*1e-3
    def hist(i):
        d = np.array(mbs.GetSensorStoredData(ids["sens"][i]))
        k = np.rint(d[:, 0] / period)
        keep = np.abs(d[:, 0] - k * period) < 0.25 * args.h
        d = d[keep]
        d[:, 0] = k[keep] * period
        _, first = np.unique(np.rint(d[:, 0] / period), return_index=True)
        return d[first]

    h2, h12, h13, h23 = hist(2), hist(12), hist(13), hist(23)
    n = min(len(h12), len(h23))
    out = np.column_stack([h12[:n, 0], h12[:n, 1:4], h23[:n, 1:4]])
    np.savetxt(args.out, out, delimiter=",", header="t,x12,y12,z12,x23,y23,z23",
               comments="", fmt="%.16e")

    # checks of the scene
    l1 = np.linalg.norm(h12[:n, 1:4] - h2[:n, 1:4], axis=1)
    l2 = np.linalg.norm(h23[:n, 1:4] - h13[:n, 1:4], axis=1)
    gap12 = np.linalg.norm(h13[:n, 1:4] - h12[:n, 1:4], axis=1)
    below = np.nonzero(h23[:n, 2] < Y_FLOOR)[0]
    t_touch = h23[below[0], 0] if len(below) else float("nan")
    print(f"exudyn {exu.__version__}  h = {args.h:g} s  t_end = {args.tend:g} s  "
          f"success = {bool(success)}  t_reached = {mbs.systemData.GetTime():.6g} s")
    print(f"cpu_solve_s = {cpu_solve:.3f}  cpu_build_s = {cpu_build:.3f}  steps = {steps}  "
          f"newton_iterations = {it.newtonStepsCount}  jacobians = {it.newtonJacobiCount}  "
          f"ms_per_step = {1e3 * cpu_solve / max(steps, 1):.3f}")
    print(f"integrator: alpha_m = {solver.alphaM:g}, alpha_f = {solver.alphaF:g}, beta = {solver.newmarkBeta:g}, "
          f"gamma = {solver.newmarkGamma:g} (HHT alpha = {HHT_ALPHA:g}, rho_inf = {rho_inf:.4f}); "
          f"{'full' if args.full_newton else 'modified'} Newton, {'dense' if args.dense else 'sparse'} LU, "
          f"contact {args.contact} (flag switches {ids['flag']['switches']}, discontinuous iterations "
          f"{it.discontinuousIterationsCount} for {steps} steps)")
    print(f"samples = {n}  chord bar1 in [{l1.min():.6f}, {l1.max():.6f}]  "
          f"chord bar2 in [{l2.min():.6f}, {l2.max():.6f}]  |x13-x12| max = {gap12.max():.2e}")
    print(f"node 23 first below y = -1.8 at t = {t_touch:.3f} s;  max |z12| = {np.abs(h12[:n, 3]).max():.4e} m;  "
          f"min y23 = {h23[:n, 2].min():.5f} m")
    print(f"csv = {args.out}")
    return 0 if success else 1


if __name__ == "__main__":
    sys.exit(main())
