"""Write the gmsh test models of tests/models.rs with gmsh itself (PyPI `gmsh`).

    python3 -m venv target/gmsh-venv && target/gmsh-venv/bin/pip install gmsh
    target/gmsh-venv/bin/python tests/models/make_msh.py

writes, next to this script, in MSH 4.1 ASCII and binary:
  plate_hole.msh / plate_hole_binary.msh   a 2D plate 0.2 x 0.1 m with a hole of radius
      0.025 m at its centre, triangles; physical curves "clamp" (x = 0) and "tip" (x = 0.2),
      physical surface "plate".
  bracket.msh / bracket_binary.msh         a 3D L bracket (a 0.1 x 0.02 x 0.02 m arm along x
      and a 0.02 x 0.02 x 0.06 m upright at its far end), tetrahedra; physical surfaces
      "clamp" (x = 0) and "load" (the top of the upright, z = 0.08), physical volume "bracket".
"""

import os
import gmsh

HERE = os.path.dirname(os.path.abspath(__file__))


def faces_at(dim, box, eps=1e-6):
    """Tags of the entities of `dim` inside the box [x0, y0, z0, x1, y1, z1]."""
    lo, hi = box[:3], box[3:]
    tags = gmsh.model.getEntitiesInBoundingBox(
        lo[0] - eps, lo[1] - eps, lo[2] - eps, hi[0] + eps, hi[1] + eps, hi[2] + eps, dim
    )
    return [t for _, t in tags]


def save(stem):
    for binary, suffix in [(0, ""), (1, "_binary")]:
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", binary)
        gmsh.write(os.path.join(HERE, f"{stem}{suffix}.msh"))


def plate_hole():
    gmsh.clear()
    gmsh.model.add("plate_hole")
    occ = gmsh.model.occ
    plate = occ.addRectangle(0, 0, 0, 0.2, 0.1)
    hole = occ.addDisk(0.1, 0.05, 0, 0.025, 0.025)
    occ.cut([(2, plate)], [(2, hole)])
    occ.synchronize()
    gmsh.model.addPhysicalGroup(1, faces_at(1, [0, 0, 0, 0, 0.1, 0]), name="clamp")
    gmsh.model.addPhysicalGroup(1, faces_at(1, [0.2, 0, 0, 0.2, 0.1, 0]), name="tip")
    gmsh.model.addPhysicalGroup(2, [t for _, t in gmsh.model.getEntities(2)], name="plate")
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.02)
    gmsh.model.mesh.generate(2)
    save("plate_hole")


def bracket():
    gmsh.clear()
    gmsh.model.add("bracket")
    occ = gmsh.model.occ
    arm = occ.addBox(0, 0, 0, 0.1, 0.02, 0.02)
    upright = occ.addBox(0.08, 0, 0.02, 0.02, 0.02, 0.06)
    occ.fuse([(3, arm)], [(3, upright)])
    occ.synchronize()
    gmsh.model.addPhysicalGroup(2, faces_at(2, [0, 0, 0, 0, 0.02, 0.02]), name="clamp")
    gmsh.model.addPhysicalGroup(2, faces_at(2, [0.08, 0, 0.08, 0.1, 0.02, 0.08]), name="load")
    gmsh.model.addPhysicalGroup(3, [t for _, t in gmsh.model.getEntities(3)], name="bracket")
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.01)
    gmsh.model.mesh.generate(3)
    save("bracket")


gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
plate_hole()
bracket()
gmsh.finalize()
