#!/usr/bin/python3
"""Render the simulation demo to PNG: left the input surface at rest inside
its cage, right the same surface carried by the deformed cage; the cage's
boundary in wireframe, the fixed base as a grey slab.

    xvfb-run -a -s "-screen 0 1600x800x24" /usr/bin/python3 \\
        scripts/render-sim.py CAGE.vtu REST.obj DEFORMED.obj OUT.png

CAGE.vtu holds the rest cage with a point array "u" (the displacement).
Uses Debian's python3-vtk9.
"""
import sys

import vtk


def read(path, cls):
    r = cls()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def surface_actor(poly):
    normals = vtk.vtkPolyDataNormals()
    normals.SetInputData(poly)
    normals.SetFeatureAngle(60)
    m = vtk.vtkPolyDataMapper()
    m.SetInputConnection(normals.GetOutputPort())
    m.ScalarVisibilityOff()
    a = vtk.vtkActor()
    a.SetMapper(m)
    a.GetProperty().SetColor(0.85, 0.72, 0.55)
    a.GetProperty().SetSpecular(0.2)
    return a


def cage_actor(grid):
    geo = vtk.vtkDataSetSurfaceFilter()
    geo.SetInputData(grid)
    edges = vtk.vtkExtractEdges()
    edges.SetInputConnection(geo.GetOutputPort())
    m = vtk.vtkPolyDataMapper()
    m.SetInputConnection(edges.GetOutputPort())
    m.ScalarVisibilityOff()
    a = vtk.vtkActor()
    a.SetMapper(m)
    a.GetProperty().SetColor(0.1, 0.25, 0.6)
    a.GetProperty().SetLineWidth(1.2)
    a.GetProperty().SetOpacity(0.8)
    return a


def text(s):
    t = vtk.vtkTextActor()
    t.SetInput(s)
    t.GetTextProperty().SetFontSize(22)
    t.GetTextProperty().SetColor(0.1, 0.1, 0.1)
    t.SetPosition(14, 14)
    return t


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    cage_path, rest_path, sag_path, out = sys.argv[1:]
    cage = read(cage_path, vtk.vtkXMLUnstructuredGridReader)
    warp = vtk.vtkWarpVector()
    warp.SetInputData(cage)
    cage.GetPointData().SetActiveVectors("u")
    warp.SetScaleFactor(1.0)
    warp.Update()
    moved = warp.GetOutput()
    rest = read(rest_path, vtk.vtkOBJReader)
    sag = read(sag_path, vtk.vtkOBJReader)

    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(1600, 800)
    cam = vtk.vtkCamera()
    for i, (surf, grid, label) in enumerate(((rest, cage, "rest"),
                                             (sag, moved, "Neo-Hookean sag, base fixed"))):
        ren = vtk.vtkRenderer()
        ren.SetViewport(0.5 * i, 0, 0.5 * i + 0.5, 1)
        ren.SetBackground(1, 1, 1)
        ren.AddActor(surface_actor(surf))
        ren.AddActor(cage_actor(grid))
        ren.AddActor2D(text(label))
        ren.SetActiveCamera(cam)
        win.AddRenderer(ren)
        if i == 0:
            ren.ResetCamera()
            # Bunny-style models are y-up: look from the side, a little above.
            cam.SetViewUp(0, 1, 0)
            cam.Azimuth(-30)
            cam.Elevation(15)
            ren.ResetCamera(grid.GetBounds())
            cam.Zoom(1.25)
    win.Render()
    shot = vtk.vtkWindowToImageFilter()
    shot.SetInput(win)
    shot.Update()
    w = vtk.vtkPNGWriter()
    w.SetFileName(out)
    w.SetInputConnection(shot.GetOutputPort())
    w.Write()


if __name__ == "__main__":
    main()
