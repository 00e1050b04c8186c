"""A vertical colour bar that fills its own renderer (a strip beside the
picture, so it covers nothing): title on top, clear of the labels, black
text of one size. Shared by render-mesh.py and render-field.py."""
import vtk


def scalar_bar(table, title, title_size=16, label_size=14):
    bar = vtk.vtkScalarBarActor()
    bar.SetLookupTable(table)
    bar.SetTitle(title)
    bar.SetNumberOfLabels(5)
    bar.SetPosition(0.05, 0.15)
    bar.SetWidth(0.9)
    bar.SetHeight(0.7)
    bar.SetBarRatio(0.25)
    bar.SetVerticalTitleSeparation(10)
    bar.UnconstrainedFontSizeOn()
    for tp, size in ((bar.GetTitleTextProperty(), title_size),
                     (bar.GetLabelTextProperty(), label_size)):
        tp.SetColor(0, 0, 0)
        tp.SetFontSize(size)
        tp.ItalicOff()
        tp.ShadowOff()
    return bar
