#!/usr/bin/python3
"""Render two tet meshes of one surface side by side to PNG: souptet's
(left) and a peer's (right); top row the whole mesh, half transparent, with
the input surface inside; bottom row a cut-away (the tets wholly on one
side of a plane through the middle) with the input clipped there. Every
tet is coloured by its own min dihedral angle, computed here, so meshes
without that cell array (TetGen's) are coloured the same way.

    xvfb-run -a -s "-screen 0 1600x1600x24" /usr/bin/python3 \\
        scripts/render-frontier.py LEFT.vtu RIGHT.ele|.vtu SURFACE OUT.png

Meshes: .vtu (VTK XML) or a TetGen .node/.ele pair (give the .ele).
Colours as scripts/render-mesh.py: blue-green-yellow-red = 0..70 degrees.
"""
import importlib.util
import math
import os
import sys

import vtk

_spec = importlib.util.spec_from_file_location(
    "render_mesh", os.path.join(os.path.dirname(os.path.abspath(__file__)), "render-mesh.py"))
rm = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(rm)


def _rows(path):
    with open(path) as f:
        for line in f:
            line = line.split("#")[0].split()
            if line:
                yield line


def read_tetgen(ele):
    stem = ele[:-4]
    rows = _rows(stem + ".node")
    n = int(next(rows)[0])
    pts = vtk.vtkPoints()
    base = None
    for _ in range(n):
        r = next(rows)
        if base is None:
            base = int(r[0])
        pts.InsertNextPoint(float(r[1]), float(r[2]), float(r[3]))
    rows = _rows(ele)
    m = int(next(rows)[0])
    g = vtk.vtkUnstructuredGrid()
    g.SetPoints(pts)
    for _ in range(m):
        r = next(rows)
        g.InsertNextCell(vtk.VTK_TETRA, 4, [int(x) - base for x in r[1:5]])
    return g


def read_mesh(path):
    if path.endswith(".ele"):
        return read_tetgen(path)
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def min_dihedral(p):
    """The smallest of the six dihedral angles of the tet p[0..3], degrees."""
    best = 180.0
    for i, j in ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)):
        k, l = [x for x in range(4) if x not in (i, j)]
        e = _sub(p[j], p[i])
        n1 = _cross(e, _sub(p[k], p[i]))
        n2 = _cross(e, _sub(p[l], p[i]))
        d = math.sqrt(_dot(n1, n1) * _dot(n2, n2))
        if d == 0.0:
            return 0.0
        c = max(-1.0, min(1.0, _dot(n1, n2) / d))
        best = min(best, math.degrees(math.acos(c)))
    return best


def colour_by_min_dihedral(g):
    a = vtk.vtkDoubleArray()
    a.SetName("min_dihedral")
    pts = g.GetPoints()
    for c in range(g.GetNumberOfCells()):
        ids = g.GetCell(c).GetPointIds()
        a.InsertNextValue(min_dihedral([pts.GetPoint(ids.GetId(k)) for k in range(4)]))
    g.GetCellData().AddArray(a)


def label(text):
    t = vtk.vtkTextActor()
    t.SetInput(text)
    t.GetTextProperty().SetColor(0, 0, 0)
    t.GetTextProperty().SetFontSize(22)
    t.SetPosition(12, 12)
    return t


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    left, right, surf_path, out = sys.argv[1:]
    surface = rm.read_surface(surf_path)
    table = rm.lut()
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(1600, 1600)
    cam = None
    for col, (path, name) in enumerate(((left, "souptet"), (right, "alpha wrap + TetGen"))):
        g = read_mesh(path)
        colour_by_min_dihedral(g)
        dmin = g.GetCellData().GetArray("min_dihedral").GetRange()[0]
        top = vtk.vtkRenderer()
        top.SetViewport(0.5 * col, 0.5, 0.5 * col + 0.5, 1.0)
        top.AddActor(rm.mesh_actor(g, 0.55, table))
        top.AddActor(rm.surface_actor(surface, 1.0))
        top.AddActor2D(label("%s: %d tets, min dihedral %.1f deg" % (
            name, g.GetNumberOfCells(), dmin)))
        b = surface.GetBounds()
        plane = vtk.vtkPlane()
        plane.SetOrigin(0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5]))
        plane.SetNormal(0, 0, 1)
        keep = vtk.vtkExtractGeometry()
        keep.SetInputData(g)
        keep.SetImplicitFunction(plane)
        keep.ExtractInsideOn()
        keep.ExtractBoundaryCellsOff()
        keep.Update()
        clip = vtk.vtkClipPolyData()
        clip.SetInputData(surface)
        clip.SetClipFunction(plane)
        clip.InsideOutOn()
        clip.Update()
        bottom = vtk.vtkRenderer()
        bottom.SetViewport(0.5 * col, 0.0, 0.5 * col + 0.5, 0.5)
        bottom.AddActor(rm.mesh_actor(keep.GetOutput(), 1.0, table))
        bottom.AddActor(rm.surface_actor(clip.GetOutput(), 1.0))
        if col == 1:
            bar = vtk.vtkScalarBarActor()
            bar.SetLookupTable(table)
            bar.SetTitle("min dihedral")
            bar.SetNumberOfLabels(4)
            bar.SetWidth(0.08)
            bar.SetHeight(0.5)
            bar.GetTitleTextProperty().SetColor(0, 0, 0)
            bar.GetLabelTextProperty().SetColor(0, 0, 0)
            bottom.AddActor2D(bar)
        for ren in (top, bottom):
            ren.SetBackground(1, 1, 1)
            win.AddRenderer(ren)
            if cam is None:
                ren.ResetCamera()
                cam = ren.GetActiveCamera()
                cam.Azimuth(30)
                cam.Elevation(20)
                ren.ResetCamera()
            else:
                ren.SetActiveCamera(cam)
    win.Render()
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.Update()
    w = vtk.vtkPNGWriter()
    w.SetFileName(out)
    w.SetInputConnection(grab.GetOutputPort())
    w.Write()


if __name__ == "__main__":
    main()
