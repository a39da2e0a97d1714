"""Generate the committed mesh files of studies/ with gmsh (not a runtime
dependency of adhesive_contact, which reads them with meshio).

    pip install gmsh
    python studies/meshes/make_meshes.py

On this machine the gmsh wheel (4.15) ran without extra system libraries;
where it does not import (missing libGLU, libXcursor, ...) install them
with ``apt-get install libglu1-mesa libxcursor1 libxinerama1 libxft2``.

Meshes (first-order simplices; named physical groups on the boundary):

- ``half_disc.msh`` (format 4.1) and ``half_disc_v22.msh`` (the same mesh
  in format 2.2): the lower half of the disc of radius 1 centred at
  (0, 1); groups ``top`` (the flat side y = 1) and ``foot`` (the arc).
- ``cylinder_foot.msh`` (4.1): the lower half of the cylinder of radius 1
  around the axis x = 0, y = 1, for 0 ≤ z ≤ 1; groups ``top`` (y = 1),
  ``foot`` (the curved side), ``front`` (z = 0) and ``back`` (z = 1).
- ``plate_with_hole.msh`` (4.1): the square [0, 1]² without the disc of
  radius 0.25 around (0.5, 0.5); groups ``left``, ``right``, ``bottom``,
  ``top`` and ``hole`` (for manufactured studies on an unstructured mesh
  with a curved side).
"""

from pathlib import Path

import gmsh

HERE = Path(__file__).parent


def _side(dim, tags, test):
    """The entities of ``tags`` (dim) whose centre of mass passes ``test``."""
    return [t for t in tags if test(gmsh.model.occ.getCenterOfMass(dim, t))]


def _write(name, version=4.1):
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.write(str(HERE / name))


def half_disc(size=0.1):
    gmsh.model.add("half_disc")
    occ = gmsh.model.occ
    disc = occ.addDisk(0.0, 1.0, 0.0, 1.0, 1.0)
    box = occ.addRectangle(-1.5, 1.0, 0.0, 3.0, 1.5)
    occ.cut([(2, disc)], [(2, box)])
    occ.synchronize()
    curves = [t for _, t in gmsh.model.getEntities(1)]
    top = _side(1, curves, lambda c: abs(c[1] - 1.0) < 1e-9)
    foot = [c for c in curves if c not in top]
    gmsh.model.addPhysicalGroup(1, top, name="top")
    gmsh.model.addPhysicalGroup(1, foot, name="foot")
    gmsh.model.addPhysicalGroup(2, [t for _, t in gmsh.model.getEntities(2)], name="body")
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(2)
    _write("half_disc.msh", 4.1)
    _write("half_disc_v22.msh", 2.2)


def cylinder_foot(size=0.25):
    gmsh.model.add("cylinder_foot")
    occ = gmsh.model.occ
    cyl = occ.addCylinder(0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0)
    box = occ.addBox(-1.5, 1.0, -0.5, 3.0, 1.5, 2.0)
    occ.cut([(3, cyl)], [(3, box)])
    occ.synchronize()
    faces = [t for _, t in gmsh.model.getEntities(2)]
    top = _side(2, faces, lambda c: abs(c[1] - 1.0) < 1e-9)
    front = _side(2, faces, lambda c: abs(c[2]) < 1e-9)
    back = _side(2, faces, lambda c: abs(c[2] - 1.0) < 1e-9)
    foot = [f for f in faces if f not in top + front + back]
    for name, tags in (("top", top), ("foot", foot), ("front", front), ("back", back)):
        gmsh.model.addPhysicalGroup(2, tags, name=name)
    gmsh.model.addPhysicalGroup(3, [t for _, t in gmsh.model.getEntities(3)], name="body")
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(3)
    _write("cylinder_foot.msh", 4.1)


def plate_with_hole(size=0.125):
    gmsh.model.add("plate_with_hole")
    occ = gmsh.model.occ
    square = occ.addRectangle(0.0, 0.0, 0.0, 1.0, 1.0)
    hole = occ.addDisk(0.5, 0.5, 0.0, 0.25, 0.25)
    occ.cut([(2, square)], [(2, hole)])
    occ.synchronize()
    curves = [t for _, t in gmsh.model.getEntities(1)]
    sides = {
        "left": _side(1, curves, lambda c: abs(c[0]) < 1e-9),
        "right": _side(1, curves, lambda c: abs(c[0] - 1.0) < 1e-9),
        "bottom": _side(1, curves, lambda c: abs(c[1]) < 1e-9),
        "top": _side(1, curves, lambda c: abs(c[1] - 1.0) < 1e-9),
    }
    named = sum(sides.values(), [])
    sides["hole"] = [c for c in curves if c not in named]
    for name, tags in sides.items():
        gmsh.model.addPhysicalGroup(1, tags, name=name)
    gmsh.model.addPhysicalGroup(2, [t for _, t in gmsh.model.getEntities(2)], name="body")
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(2)
    _write("plate_with_hole.msh", 4.1)


if __name__ == "__main__":
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    for make in (half_disc, cylinder_foot, plate_with_hole):
        gmsh.clear()
        make()
    gmsh.finalize()
