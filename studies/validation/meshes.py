"""Graded triangle meshes of a rectangle for the validation studies.

    python studies/validation/meshes.py

writes ``studies/validation/meshes/block_L{level}.msh`` (gmsh 2.2, named
groups ``left``, ``right``, ``bottom``, ``top``): the rectangle
[0, W] × [0, H] with lines at x_i, y_j that are evenly spaced (spacing
h_c) over [0, FINE] near the corner (0, 0), where the contact of the Lee &
Radok study lies, and grow geometrically (ratio GROWTH) beyond it; each
cell of the grid is split by a diagonal. Level l halves h_c (l = 0:
h_c = 0.01). Only numpy and meshio (no gmsh needed).
"""

from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
#: the block, the fine zone at the corner (0, 0), the growth beyond it
W, H, FINE, GROWTH = 1.0, 1.0, 0.12, 1.15
H_C = {0: 0.01, 1: 0.005, 2: 0.0025}


def graded(length, fine, hc, growth):
    """Lines 0 = s_0 < … < s_n = length: spacing hc up to ``fine``, then
    growing by ``growth`` per cell (the last cell stretched to end at
    ``length``)."""
    lines = list(np.arange(0.0, fine + 0.5 * hc, hc))
    h = hc
    while lines[-1] < length:
        h *= growth
        lines.append(lines[-1] + h)
    lines[-1] = length
    if lines[-1] - lines[-2] < 0.5 * h:   # no sliver at the end
        del lines[-2]
    return np.array(lines)


def block(hc, width=W, height=H, fine=FINE, growth=GROWTH):
    """A meshio Mesh of the graded rectangle, with the four named sides."""
    import meshio

    x = graded(width, fine, hc, growth)
    y = graded(height, fine, hc, growth)
    nx, ny = x.size, y.size
    X, Y = np.meshgrid(x, y, indexing="ij")
    points = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], axis=1)
    node = np.arange(nx * ny).reshape(nx, ny)
    a, b = node[:-1, :-1].ravel(), node[1:, :-1].ravel()
    c, d = node[1:, 1:].ravel(), node[:-1, 1:].ravel()
    triangles = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    sides = {"bottom": node[:, 0], "top": node[:, -1], "left": node[0, :],
             "right": node[-1, :]}
    lines, tags = [], []
    for tag, (name, chain) in enumerate(sides.items(), start=1):
        lines.append(np.stack([chain[:-1], chain[1:]], axis=1))
        tags.append(np.full(chain.size - 1, tag))
    body_tag = len(sides) + 1
    field_data = {name: np.array([tag, 1]) for tag, name in enumerate(sides, start=1)}
    field_data["body"] = np.array([body_tag, 2])
    line_tags = np.concatenate(tags)
    triangle_tags = np.full(triangles.shape[0], body_tag)
    return meshio.Mesh(points, [("line", np.concatenate(lines)), ("triangle", triangles)],
                       cell_data={"gmsh:physical": [line_tags, triangle_tags],
                                  "gmsh:geometrical": [line_tags, triangle_tags]},
                       field_data=field_data)


def write(level, folder=HERE / "meshes"):
    """Write block_L{level}.msh (atomically); its path."""
    folder.mkdir(exist_ok=True)
    path = folder / f"block_L{level}.msh"
    partial = path.with_suffix(".msh.partial")
    block(H_C[level]).write(partial, file_format="gmsh22", binary=False)
    partial.replace(path)
    return path


if __name__ == "__main__":
    for level in H_C:
        path = write(level)
        print(f"{path.relative_to(HERE.parent.parent)}: h_c = {H_C[level]:g}")
