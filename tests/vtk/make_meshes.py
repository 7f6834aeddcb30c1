"""Writes the VTK mesh files of tests/data/vtk/ with VTK's own writers and with meshio, the
writers users' files come from (tests/vtk_files.rs reads them and compares with the mesh
described here, which it writes out by hand too), and models/meshes/quarter_cylinder.vtu.

The mesh: [0, 4] x [0, 1] in 4 x 2 quads (points i + 5 j, at (i, j / 2)), the quads with odd
i + j written clockwise; lines on the four sides in order around the body (bottom left to
right, right bottom to top, top right to left, left top to bottom); vertices at the corners
(bottom left, bottom right, top right, top left). Cell data `side`: 0 on the quads, 1 2 3 4 on
the bottom, right, top and left lines, 5 6 7 8 on the corner vertices. Point data `region`: 1
on the points with x = 0, else 0.

The quarter cylinder: the ring 1 <= r <= 2, 0 <= theta <= 90 deg in 4 x 16 quads (radial x
around, point i + 5 j at r = 1 + i / 4, theta = j pi / 32), counter-clockwise; cell data
`face`: 0 on the quads, 1 on the bore lines, 2 on the outer arc, 3 on the cut y = 0, 4 on the
cut x = 0, 5 on a vertex at the bore point (1, 0). Written as ParaView's Save Data with Data
Mode "Binary" and zlib compression.

Usage: python3 tests/vtk/make_meshes.py   (needs `pip install vtk meshio`; VTK 9.7.2 and
meshio 5.3.5 wrote the files checked in)
"""
import math
from pathlib import Path

import meshio
import vtk

OUT = Path(__file__).resolve().parent.parent / "data" / "vtk"
MODELS = Path(__file__).resolve().parent.parent.parent / "models" / "meshes"


def point(i, j):
    return i + 5 * j


def grid():
    points = vtk.vtkPoints()
    points.SetDataTypeToDouble()
    for j in range(3):
        for i in range(5):
            points.InsertNextPoint(float(i), j / 2, 0.0)
    g = vtk.vtkUnstructuredGrid()
    g.SetPoints(points)
    side = vtk.vtkIntArray()
    side.SetName("side")
    for j in range(2):
        for i in range(4):
            ids = [point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)]
            if (i + j) % 2:
                ids = [ids[0], ids[3], ids[2], ids[1]]
            g.InsertNextCell(vtk.VTK_QUAD, 4, ids)
            side.InsertNextValue(0)
    sides = [
        [(i, 0, i + 1, 0) for i in range(4)],
        [(4, j, 4, j + 1) for j in range(2)],
        [(4 - i, 2, 3 - i, 2) for i in range(4)],
        [(0, 2 - j, 0, 1 - j) for j in range(2)],
    ]
    for value, lines in enumerate(sides, start=1):
        for a, b, c, d in lines:
            g.InsertNextCell(vtk.VTK_LINE, 2, [point(a, b), point(c, d)])
            side.InsertNextValue(value)
    for value, (i, j) in enumerate([(0, 0), (4, 0), (4, 2), (0, 2)], start=5):
        g.InsertNextCell(vtk.VTK_VERTEX, 1, [point(i, j)])
        side.InsertNextValue(value)
    g.GetCellData().AddArray(side)
    region = vtk.vtkIntArray()
    region.SetName("region")
    for j in range(3):
        for i in range(5):
            region.InsertNextValue(1 if i == 0 else 0)
    g.GetPointData().AddArray(region)
    return g


def quarter_cylinder():
    points = vtk.vtkPoints()
    points.SetDataTypeToDouble()
    for j in range(17):
        theta = j * math.pi / 32
        for i in range(5):
            r = 1 + i / 4
            points.InsertNextPoint(r * math.cos(theta), r * math.sin(theta), 0.0)
    g = vtk.vtkUnstructuredGrid()
    g.SetPoints(points)
    face = vtk.vtkIntArray()
    face.SetName("face")

    def p(i, j):
        return i + 5 * j

    for j in range(16):
        for i in range(4):
            g.InsertNextCell(vtk.VTK_QUAD, 4, [p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)])
            face.InsertNextValue(0)
    lines = [
        (1, [(p(0, j + 1), p(0, j)) for j in range(16)]),
        (2, [(p(4, j), p(4, j + 1)) for j in range(16)]),
        (3, [(p(i, 0), p(i + 1, 0)) for i in range(4)]),
        (4, [(p(i + 1, 16), p(i, 16)) for i in range(4)]),
    ]
    for value, ends in lines:
        for a, b in ends:
            g.InsertNextCell(vtk.VTK_LINE, 2, [a, b])
            face.InsertNextValue(value)
    g.InsertNextCell(vtk.VTK_VERTEX, 1, [p(0, 0)])
    face.InsertNextValue(5)
    g.GetCellData().AddArray(face)
    return g


def xml(g, name, mode, encode, compressor, folder=OUT):
    writer = vtk.vtkXMLUnstructuredGridWriter()
    writer.SetFileName(str(folder / name))
    writer.SetInputData(g)
    getattr(writer, "SetDataModeTo" + mode)()
    writer.SetEncodeAppendedData(encode)
    getattr(writer, "SetCompressorTypeTo" + compressor)()
    writer.Write()


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    g = grid()
    xml(g, "rect_binary_zlib.vtu", "Binary", True, "ZLib")
    xml(g, "rect_binary_lz4.vtu", "Binary", True, "LZ4")
    xml(g, "rect_binary_lzma.vtu", "Binary", True, "LZMA")
    xml(g, "rect_appended_base64.vtu", "Appended", True, "None")
    # ParaView's and VTK's default: appended raw binary, which impact refuses
    xml(g, "rect_appended_raw.vtu", "Appended", False, "ZLib")
    legacy = vtk.vtkUnstructuredGridWriter()
    legacy.SetFileName(str(OUT / "rect_legacy_binary.vtk"))
    legacy.SetInputData(g)
    legacy.SetFileTypeToBinary()
    legacy.Write()
    mesh = meshio.read(OUT / "rect_appended_raw.vtu")
    meshio.write(OUT / "rect_meshio_binary.vtk", mesh, binary=True)
    meshio.write(OUT / "rect_meshio_zlib.vtu", mesh, binary=True)
    MODELS.mkdir(parents=True, exist_ok=True)
    xml(quarter_cylinder(), "quarter_cylinder.vtu", "Binary", True, "ZLib", MODELS)


if __name__ == "__main__":
    main()
