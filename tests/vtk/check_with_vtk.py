"""Reads the frames of `cargo test --release --lib vtk_reader_check -- --ignored` with VTK's own
XML reader (the reader ParaView uses) and compares every array, bit for bit, with the values the
test wrote, and each frame's time (field data TimeValue) with the time it was written at. The expected values are computed here from the test's formula, independently of
impact's own reader (src/output/vtu.rs).

Usage: python3 tests/vtk/check_with_vtk.py [output/vtk_reader_check]   (needs `pip install vtk`)
"""
import sys
from pathlib import Path

import vtk
from vtk.util.numpy_support import vtk_to_numpy
import numpy as np

TIMES = [0.0, 1e-5, 1.0 / 3.0]


def small_grid():
    points = [(0, 0), (1, 0), (2, 0), (0, 1), (1, 1), (2, 1), (3, 0.5), (4, 0.5)]
    return points, [[0, 1, 4, 3], [1, 2, 5, 4]], [[6, 7]]


def block_grid():
    n = 64
    points = [(i % n, i // n) for i in range(n * n)]
    quads = [[a, a + 1, a + n + 1, a + n] for j in range(n - 1) for a in (j * n + i for i in range(n - 1))]
    lines = [[i, i + 1] for i in range(127)]
    return points, quads, lines


def value(k, field, i, c):
    # the formula of Frame::new in src/output/vtk.rs
    return (k + 1.0) * (1.0 / 3.0 + field) + i * 1e-3 - c * 1e-7


def expected(k, points, cells):
    np_, nc = len(points), cells
    arrays = {}
    names = ["displacement", "velocity", "acceleration", "contact_force"]
    for f, name in enumerate(names):
        arrays[name] = np.array([[value(k, f, i, 0), value(k, f, i, 1), 0.0] for i in range(np_)])
    arrays["gap"] = np.array([value(k, 4, i, 0) for i in range(np_)])
    arrays["contact_status"] = np.array([value(k, 5, i, 0) for i in range(np_)])
    arrays["reference_coordinates"] = np.array([[value(k, 10, i, 0), value(k, 10, i, 1), 0.0] for i in range(np_)])
    arrays["stress"] = np.array([[value(k, 6, i, c) for c in range(6)] for i in range(nc)])
    for f, name in zip((7, 8, 9), ("von_mises", "eq_plastic_strain", "pressure")):
        arrays[name] = np.array([value(k, f, i, 0) for i in range(nc)])
    return arrays


def check(pvd: Path, grid):
    points, quads, lines = grid
    cells = len(quads) + len(lines)
    text = pvd.read_text()
    files = [line.split('file="')[1].split('"')[0] for line in text.splitlines() if "<DataSet" in line]
    assert len(files) == 3, files
    for k, name in enumerate(files):
        reader = vtk.vtkXMLUnstructuredGridReader()
        reader.SetFileName(str(pvd.parent / name))
        reader.Update()
        grid_out = reader.GetOutput()
        # the frame's own time (field data TimeValue), as ParaView shows it for a .vtu alone
        time = grid_out.GetFieldData().GetArray("TimeValue")
        assert time is not None, (name, "no TimeValue")
        assert time.GetNumberOfTuples() == 1 and time.GetValue(0) == TIMES[k], (name, time.GetValue(0))
        assert grid_out.GetNumberOfPoints() == len(points), name
        assert grid_out.GetNumberOfCells() == cells, name
        xyz = vtk_to_numpy(grid_out.GetPoints().GetData())
        assert np.array_equal(xyz, np.array([[x, y, 0.0] for x, y in points], dtype=float)), name
        for c, nodes in enumerate(quads + lines):
            cell = grid_out.GetCell(c)
            assert cell.GetCellType() == (9 if c < len(quads) else 3), (name, c)
            ids = [cell.GetPointId(j) for j in range(cell.GetNumberOfPoints())]
            assert ids == nodes, (name, c, ids, nodes)
        point_data, cell_data = grid_out.GetPointData(), grid_out.GetCellData()
        assert point_data.GetVectors().GetName() == "displacement", name
        for array_name, values in expected(k, points, cells).items():
            data = point_data if values.shape[0] == len(points) and array_name not in (
                "stress", "von_mises", "eq_plastic_strain", "pressure") else cell_data
            read = vtk_to_numpy(data.GetArray(array_name))
            assert read.dtype == np.float64, (name, array_name, read.dtype)
            assert np.array_equal(read.reshape(values.shape), values), (name, array_name)
    return len(files)


def main():
    root = Path(sys.argv[1] if len(sys.argv) > 1 else "output/vtk_reader_check")
    total = 0
    for compression in ("none", "lz4", "zlib"):
        for series, grid in (("small", small_grid()), ("blocks", block_grid())):
            total += check(root / compression / f"{series}.pvd", grid)
            print(f"{compression:5s} {series:7s}: 3 frames read by VTK {vtk.vtkVersion.GetVTKVersion()}, every array bit-exact, each with its TimeValue")
    print(f"{total} frames checked")


if __name__ == "__main__":
    main()
