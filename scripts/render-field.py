#!/usr/bin/python3
"""Render a distance field (.vti) to PNG: the iso-surface at a distance and
a slice through the middle, coloured by distance.

    xvfb-run -a /usr/bin/python3 scripts/render-field.py FIELD.vti OUT.png [ISO]

ISO defaults to one voxel. Uses Debian's python3-vtk9.
"""
import sys

import vtk

from render_bar import scalar_bar


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    src, out = sys.argv[1], sys.argv[2]
    reader = vtk.vtkXMLImageDataReader()
    reader.SetFileName(src)
    reader.Update()
    img = reader.GetOutput()
    if img.GetNumberOfPoints() == 0:
        sys.exit("render-field.py: %s: no data" % src)
    iso = float(sys.argv[3]) if len(sys.argv) > 3 else img.GetSpacing()[0]
    lo, hi = img.GetPointData().GetScalars().GetRange()

    contour = vtk.vtkFlyingEdges3D()
    contour.SetInputData(img)
    contour.SetValue(0, iso)
    cmap = vtk.vtkPolyDataMapper()
    cmap.SetInputConnection(contour.GetOutputPort())
    cmap.ScalarVisibilityOff()
    surf = vtk.vtkActor()
    surf.SetMapper(cmap)
    surf.GetProperty().SetColor(0.85, 0.75, 0.6)

    bounds = img.GetBounds()
    plane = vtk.vtkPlane()
    plane.SetOrigin(0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
                    0.5 * (bounds[4] + bounds[5]))
    plane.SetNormal(0, 0, 1)
    cut = vtk.vtkCutter()
    cut.SetInputData(img)
    cut.SetCutFunction(plane)
    smap = vtk.vtkPolyDataMapper()
    smap.SetInputConnection(cut.GetOutputPort())
    smap.SetScalarRange(lo, hi)
    slice_actor = vtk.vtkActor()
    slice_actor.SetMapper(smap)

    ren = vtk.vtkRenderer()
    ren.SetBackground(1, 1, 1)
    ren.SetViewport(0.0, 0.0, 0.82, 1.0)
    ren.AddActor(surf)
    ren.AddActor(slice_actor)

    # The slice's colours, in a strip of their own beside the picture.
    signed = lo < 0.0
    bar = scalar_bar(smap.GetLookupTable(), "signed\ndistance" if signed else "distance",
                     14, 12)
    legend = vtk.vtkRenderer()
    legend.SetBackground(1, 1, 1)
    legend.SetViewport(0.82, 0.0, 1.0, 1.0)
    legend.AddActor2D(bar)
    ren.GetActiveCamera().Azimuth(30)
    ren.GetActiveCamera().Elevation(20)
    ren.ResetCamera()
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.AddRenderer(ren)
    win.AddRenderer(legend)
    win.SetSize(900, 600)
    win.Render()
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.Update()
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(out)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()


if __name__ == "__main__":
    main()
