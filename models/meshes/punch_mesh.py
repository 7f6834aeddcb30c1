#!/usr/bin/env python3
"""Writes the Gmsh MSH 4.1 quad meshes of Shield's flat punch problem: a cylinder of radius
and height R = 10 a under a punch of radius a (a = 1e-3 m), axisymmetric section
[0, R] x [-R, 0], the elements graded toward the punch edge (r = a, y = 0). Level k splits
every element of level 0 in 2^k x 2^k, so the family refines by 2 everywhere (a grid
convergence index needs a fixed refinement ratio). Usage: punch_mesh.py LEVEL OUT.msh"""
import sys

A = 1e-3
R = 10 * A


def graded(length, n, ratio, fine_at_start):
    """n sizes in geometric progression over length, largest / smallest = ratio."""
    q = ratio ** (1.0 / (n - 1)) if n > 1 else 1.0
    sizes = [q ** i for i in range(n)]
    total = sum(sizes)
    sizes = [s * length / total for s in sizes]
    return sizes if fine_at_start else sizes[::-1]


def split(coords, k):
    for _ in range(k):
        out = [coords[0]]
        for a, b in zip(coords, coords[1:]):
            out += [(a + b) / 2, b]
        coords = out
    return coords


def cumulative(start, sizes):
    c = [start]
    for s in sizes:
        c.append(c[-1] + s)
    return c


def main():
    level, path = int(sys.argv[1]), sys.argv[2]
    # r: 0..a, 8 elements, fine at a (4:1); a..R, 16 elements, fine at a (40:1)
    xs = cumulative(0.0, graded(A, 8, 4.0, False))
    xs = xs[:-1] + cumulative(A, graded(R - A, 16, 40.0, True))
    xs[-1] = R
    # y: 0 down to -R, 20 elements, fine at the top (60:1)
    ys = cumulative(0.0, [-s for s in graded(R, 20, 60.0, True)])
    ys[-1] = -R
    xs, ys = split(xs, level), split(ys, level)
    nx, ny = len(xs) - 1, len(ys) - 1
    node = lambda i, j: 1 + j * (nx + 1) + i
    # curves: 1 axis (r = 0), 2 bottom, 3 right, 4 top; surface 1
    lines = {1: [], 2: [], 3: [], 4: []}
    for j in range(ny):  # axis, body on the left going down (y decreasing)... oriented by the reader
        lines[1].append((node(0, j), node(0, j + 1)))
        lines[3].append((node(nx, j + 1), node(nx, j)))
    for i in range(nx):
        lines[2].append((node(i, ny), node(i + 1, ny)))
        lines[4].append((node(i + 1, 0), node(i, 0)))
    quads = []
    for j in range(ny):
        for i in range(nx):
            # counter-clockwise: y decreases with j
            quads.append((node(i, j + 1), node(i + 1, j + 1), node(i + 1, j), node(i, j)))
    nn = (nx + 1) * (ny + 1)
    out = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$PhysicalNames", "5",
           '1 1 "axis"', '1 2 "bottom"', '1 3 "right"', '1 4 "top"', '2 5 "block"',
           "$EndPhysicalNames", "$Entities", "0 4 1 0"]
    for c in range(1, 5):
        out.append(f"{c} 0 {-R} 0 {R} 0 0 1 {c} 0")
    out.append(f"1 0 {-R} 0 {R} 0 0 1 5 4 1 2 3 4")
    out += ["$EndEntities", "$Nodes", f"1 {nn} 1 {nn}", f"2 1 0 {nn}"]
    out += [str(k) for k in range(1, nn + 1)]
    for j in range(ny + 1):
        for i in range(nx + 1):
            out.append(f"{xs[i]!r} {ys[j]!r} 0")
    out.append("$EndNodes")
    ne = sum(len(v) for v in lines.values()) + len(quads)
    out += ["$Elements", f"5 {ne} 1 {ne}"]
    tag = 1
    for c in range(1, 5):
        out.append(f"1 {c} 1 {len(lines[c])}")
        for a, b in lines[c]:
            out.append(f"{tag} {a} {b}")
            tag += 1
    out.append(f"2 1 3 {len(quads)}")
    for q in quads:
        out.append(f"{tag} {q[0]} {q[1]} {q[2]} {q[3]}")
        tag += 1
    out.append("$EndElements")
    open(path, "w").write("\n".join(out) + "\n")
    print(f"{path}: {nx} x {ny} = {nx * ny} quads, smallest at the edge "
          f"{min(b - a for a, b in zip(xs, xs[1:])):.3e} m")


main()
