#!/usr/bin/python3
"""Render a tet mesh (.vtu) with its input surface to PNG, two views side
by side: left, the mesh's boundary coloured by each tet's min dihedral
angle with the input surface showing through; right, a cut-away (the tets
on one side of a plane through the middle removed) showing the interior
tets and the input surface inside them.

    xvfb-run -a -s "-screen 0 1600x800x24" /usr/bin/python3 \\
        scripts/render-mesh.py MESH.vtu OUT.png [SURFACE.obj|.ply|.stl|.off]

Colours: blue-green-yellow-red = min dihedral 0..70 degrees (red is good);
a mesh tagged with parts (soupmesh --parts: cell data "part", field data
part_name_K) is coloured by part instead, with the names in the legend.
The input surface is grey. Uses Debian's python3-vtk9.
"""
import os
import sys

import vtk

from render_bar import scalar_bar


def read_surface(path):
    ext = os.path.splitext(path)[1].lower()
    readers = {".obj": vtk.vtkOBJReader, ".ply": vtk.vtkPLYReader,
               ".stl": vtk.vtkSTLReader}
    if ext == ".off":
        # VTK has no OFF reader: parse the simple ASCII form here.
        pts, polys = vtk.vtkPoints(), vtk.vtkCellArray()
        toks = []
        with open(path) as f:
            for line in f:
                line = line.split("#")[0].strip()
                if line:
                    toks.extend(line.split())
        if toks and toks[0].upper().endswith("OFF"):
            toks = toks[1:]
        nv, nf = int(toks[0]), int(toks[1])
        i = 3
        for _ in range(nv):
            pts.InsertNextPoint(float(toks[i]), float(toks[i + 1]), float(toks[i + 2]))
            i += 3
        for _ in range(nf):
            n = int(toks[i])
            polys.InsertNextCell(n, [int(x) for x in toks[i + 1:i + 1 + n]])
            i += 1 + n
        pd = vtk.vtkPolyData()
        pd.SetPoints(pts)
        pd.SetPolys(polys)
        return pd
    if ext not in readers:
        sys.exit("render-mesh.py: %s: unknown surface format" % path)
    r = readers[ext]()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def lut():
    t = vtk.vtkLookupTable()
    t.SetHueRange(0.66, 0.0)
    t.SetTableRange(0.0, 70.0)
    t.Build()
    return t


def surface_actor(surface, opacity):
    m = vtk.vtkPolyDataMapper()
    m.SetInputData(surface)
    m.ScalarVisibilityOff()
    a = vtk.vtkActor()
    a.SetMapper(m)
    a.GetProperty().SetColor(0.55, 0.55, 0.55)
    a.GetProperty().SetOpacity(opacity)
    return a


def part_table(grid):
    """(lookup table, names) for a mesh tagged with parts, or (None, None):
    one colour a part (a qualitative palette), annotated with its name."""
    arr = grid.GetCellData().GetArray("part")
    if arr is None:
        return None, None
    fd = grid.GetFieldData()
    n = int(arr.GetRange()[1]) + 1
    names = []
    for k in range(n):
        a = fd.GetAbstractArray("part_name_%d" % k)
        if a is not None and a.GetNumberOfTuples() > 0:
            names.append(bytes(int(a.GetTuple1(i)) for i in range(a.GetNumberOfTuples()))
                         .decode("utf-8", "replace"))
        else:
            names.append("part_%d" % k)
    palette = [(0.89, 0.47, 0.20), (0.22, 0.42, 0.69), (0.30, 0.69, 0.29), (0.60, 0.31, 0.64),
               (0.97, 0.82, 0.25), (0.65, 0.34, 0.16), (0.97, 0.51, 0.75), (0.40, 0.76, 0.65),
               (0.55, 0.63, 0.80), (0.90, 0.10, 0.11)]
    t = vtk.vtkLookupTable()
    t.SetNumberOfTableValues(n)
    t.SetTableRange(-0.5, n - 0.5)
    for k in range(n):
        t.SetTableValue(k, *palette[k % len(palette)], 1.0)
        t.SetAnnotation(vtk.vtkVariant(k), names[k])
    t.IndexedLookupOn()
    t.Build()
    return t, names


def mesh_actor(grid, opacity, table, by_part=False):
    geo = vtk.vtkDataSetSurfaceFilter()
    geo.SetInputData(grid)
    m = vtk.vtkDataSetMapper()
    m.SetInputConnection(geo.GetOutputPort())
    if by_part:
        m.SetScalarModeToUseCellFieldData()
        m.SelectColorArray("part")
        m.SetLookupTable(table)
        m.UseLookupTableScalarRangeOn()
        m.ScalarVisibilityOn()
    elif grid.GetCellData().GetArray("min_dihedral") is not None:
        m.SetScalarModeToUseCellFieldData()
        m.SelectColorArray("min_dihedral")
        m.SetLookupTable(table)
        m.SetScalarRange(0.0, 70.0)
        m.ScalarVisibilityOn()
    else:
        m.ScalarVisibilityOff()
    a = vtk.vtkActor()
    a.SetMapper(m)
    a.GetProperty().EdgeVisibilityOn()
    a.GetProperty().SetEdgeColor(0.1, 0.1, 0.1)
    a.GetProperty().SetOpacity(opacity)
    return a



def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    src, out = sys.argv[1], sys.argv[2]
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(src)
    r.Update()
    grid = r.GetOutput()
    if grid.GetNumberOfCells() == 0:
        sys.exit("render-mesh.py: %s: no tets" % src)
    surface = read_surface(sys.argv[3]) if len(sys.argv) > 3 else None
    table, names = part_table(grid)
    by_part = table is not None
    if not by_part:
        table = lut()

    # Left: the whole mesh, half transparent, the input inside.
    left = vtk.vtkRenderer()
    left.SetViewport(0.0, 0.0, 0.5, 1.0)
    left.AddActor(mesh_actor(grid, 0.55 if surface else 1.0, table, by_part))
    if surface:
        left.AddActor(surface_actor(surface, 1.0))

    # The view first: the cut-away's plane faces the camera, so its cut is
    # seen face-on from any model's orientation (a fixed z plane was seen
    # edge-on on models whose z is the view's up).
    left.ResetCamera(grid.GetBounds())
    cam = left.GetActiveCamera()
    cam.Azimuth(30)
    cam.Elevation(20)
    cam.OrthogonalizeViewUp()
    left.ResetCamera(grid.GetBounds())

    # Right: the tets wholly on the far side of a plane through the middle
    # (whole cells, so the interior tets show as they are), and the input
    # clipped at the plane: it shows where the removed tets crossing the
    # plane held it. vtkPlane's inside is behind its normal: the normal
    # points at the camera, so the near half goes.
    b = grid.GetBounds()
    d = cam.GetDirectionOfProjection()
    plane = vtk.vtkPlane()
    plane.SetOrigin(0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5]))
    plane.SetNormal(-d[0], -d[1], -d[2])
    keep = vtk.vtkExtractGeometry()
    keep.SetInputData(grid)
    keep.SetImplicitFunction(plane)
    keep.ExtractInsideOn()
    keep.ExtractBoundaryCellsOff()
    keep.Update()
    right = vtk.vtkRenderer()
    right.SetViewport(0.5, 0.0, 0.9, 1.0)
    right.AddActor(mesh_actor(keep.GetOutput(), 1.0, table, by_part))
    if surface:
        clip = vtk.vtkClipPolyData()
        clip.SetInputData(surface)
        clip.SetClipFunction(plane)
        clip.InsideOutOn()
        clip.Update()
        right.AddActor(surface_actor(clip.GetOutput(), 1.0))
    right.SetActiveCamera(cam)
    left.SetViewport(0.0, 0.0, 0.5, 1.0)

    # The colour bar in a strip of its own, so it covers no mesh; its
    # title above the bar, clear of the labels.
    legend = vtk.vtkRenderer()
    legend.SetViewport(0.9, 0.0, 1.0, 1.0)
    if by_part:
        # each part's name in its colour, top down (the first 20)
        for k, name in enumerate(names[:20]):
            t = vtk.vtkTextActor()
            t.SetInput(name if k < 19 or len(names) == 20 else "... %d more" % (len(names) - 19))
            t.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
            t.SetPosition(0.08, 0.88 - 0.04 * k)
            tp = t.GetTextProperty()
            tp.SetFontSize(16)
            tp.BoldOn()
            tp.SetColor(*table.GetTableValue(k)[:3])
            legend.AddActor2D(t)
    else:
        legend.AddActor2D(scalar_bar(table, "min dihedral\n(degrees)"))

    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(1600, 800)
    for ren in (left, right, legend):
        ren.SetBackground(1, 1, 1)
        win.AddRenderer(ren)
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
