"""The same truss in OpenSees: a 2D model of corotational trusses with lumped nodal masses,
suddenly loaded, Newmark (gamma 1/2, beta 1/4), Newton to NormDispIncr 1e-12.

Reads a JSON model (argv[1]): nodes [[x, y]], members [[a, b]] (0-based), E (Pa), A (m^2),
mass per node (kg), fixed nodes, loads [[node, fx, fy]], h (s), steps, the watched node.
Prints JSON: the watched node's [ux, uy] after every step, and the wall time per step (s).

OpenSees's Newmark starts from the nodes' committed accelerations (zero unless set); ours
starts from a0 = M^-1 (F(0) - f_int(u0)). Both start balanced here: the loaded nodes get
a0 = F / m with setNodeAccel(..., '-commit') before the first step (f_int(u0) = 0).
"""
import json
import sys
import time

import openseespy.opensees as ops

model = json.load(open(sys.argv[1]))
ops.wipe()
ops.model("basic", "-ndm", 2, "-ndf", 2)
for i, (x, y) in enumerate(model["nodes"]):
    ops.node(i + 1, x, y)
    m = model["mass"][i]
    ops.mass(i + 1, m, m)
for i in model["fixed"]:
    ops.fix(i + 1, 1, 1)
ops.uniaxialMaterial("Elastic", 1, model["E"])
for k, (a, b) in enumerate(model["members"]):
    ops.element("corotTruss", k + 1, a + 1, b + 1, model["A"], 1)
ops.timeSeries("Constant", 1)
ops.pattern("Plain", 1, 1)
for n, fx, fy in model["loads"]:
    ops.load(n + 1, fx, fy)
for n, fx, fy in model["loads"]:
    m = model["mass"][n]
    ops.setNodeAccel(n + 1, 1, fx / m, "-commit")
    ops.setNodeAccel(n + 1, 2, fy / m, "-commit")
ops.constraints("Plain")
ops.numberer("RCM")
ops.system(model.get("system", "BandGeneral"))
ops.test("NormDispIncr", 1e-12, 50)
ops.algorithm("Newton")
ops.integrator("Newmark", 0.5, 0.25)
ops.analysis("Transient")
watched = model["watched"] + 1
history = []
start = time.perf_counter()
for step in range(model["steps"]):
    if ops.analyze(1, model["h"]) != 0:
        sys.exit(f"OpenSees failed at step {step + 1}")
    history.append([ops.nodeDisp(watched, 1), ops.nodeDisp(watched, 2)])
elapsed = time.perf_counter() - start
print(json.dumps({"history": history, "seconds_per_step": elapsed / model["steps"]}))
