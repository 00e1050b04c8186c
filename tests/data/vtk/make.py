#!/usr/bin/python3
# make.py - regenerate the foreign VTK XML files of tests/data/vtk/ that
# tests/test_vtkxml.c reads back (st_vtkxml_check, then souptet's readers).
# Needs Debian's python3-vtk9 and python3-meshio. Run from this directory.
#
#   vti_MODE_COMP_HDR[_be].vti   vtkXMLImageDataWriter: 4x3x2 points, one
#                                Float32 point array "sdf" (value 0.5*i-3),
#                                one String field array "note" = "hello"
#   vtu_MODE_COMP_HDR[_be].vtu   vtkXMLUnstructuredGridWriter: 5 points,
#                                2 tets, point array "temp" (2 components),
#                                Int32 cell array "region", String "source"
#   *_default.*                  the writers' defaults (what ParaView
#                                writes: appended base64, zlib, UInt64)
#   meshio_*.vtu                 meshio 5 with and without compression
#
# MODE: ascii, binary (inline base64), b64 (appended base64), raw
# (appended raw); COMP: none, zlib, lz4, lzma; HDR: 32 or 64 (header_type).
import vtk
import meshio
import numpy as np


def image():
    img = vtk.vtkImageData()
    img.SetExtent(0, 3, 0, 2, 0, 1)
    img.SetOrigin(0.5, 1, 2)
    img.SetSpacing(0.25, 0.25, 0.25)
    a = vtk.vtkFloatArray()
    a.SetName("sdf")
    for i in range(24):
        a.InsertNextValue(i * 0.5 - 3)
    img.GetPointData().SetScalars(a)
    s = vtk.vtkStringArray()
    s.SetName("note")
    s.InsertNextValue("hello")
    img.GetFieldData().AddArray(s)
    return img


def grid():
    pts = vtk.vtkPoints()
    for p in [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1)]:
        pts.InsertNextPoint(p)
    ug = vtk.vtkUnstructuredGrid()
    ug.SetPoints(pts)
    ug.InsertNextCell(vtk.VTK_TETRA, 4, [0, 1, 2, 3])
    ug.InsertNextCell(vtk.VTK_TETRA, 4, [1, 3, 2, 4])
    a = vtk.vtkDoubleArray()
    a.SetName("temp")
    a.SetNumberOfComponents(2)
    for i in range(5):
        a.InsertNextTuple2(i, -i)
    ug.GetPointData().AddArray(a)
    c = vtk.vtkIntArray()
    c.SetName("region")
    for i in range(2):
        c.InsertNextValue(i + 7)
    ug.GetCellData().AddArray(c)
    s = vtk.vtkStringArray()
    s.SetName("source")
    s.InsertNextValue("py")
    ug.GetFieldData().AddArray(s)
    return ug


def write(w, data, fn, mode, comp, hdr, be=False):
    w.SetInputData(data)
    w.SetFileName(fn)
    if mode == "ascii":
        w.SetDataModeToAscii()
    elif mode == "binary":
        w.SetDataModeToBinary()
    else:
        w.SetDataModeToAppended()
        w.SetEncodeAppendedData(1 if mode == "b64" else 0)
    {"none": w.SetCompressorTypeToNone, "zlib": w.SetCompressorTypeToZLib,
     "lz4": w.SetCompressorTypeToLZ4, "lzma": w.SetCompressorTypeToLZMA}[comp]()
    if hdr == 32:
        w.SetHeaderTypeToUInt32()
    else:
        w.SetHeaderTypeToUInt64()
    if be:
        w.SetByteOrderToBigEndian()
    assert w.Write() == 1


variants = [(m, c, h) for m in ["ascii", "binary", "b64", "raw"]
            for c in ["none", "zlib"] for h in [32, 64]]
variants += [(m, c, 64) for m in ["binary", "raw"] for c in ["lz4", "lzma"]]
for kind, make, W, ext in [("vti", image, vtk.vtkXMLImageDataWriter, "vti"),
                           ("vtu", grid, vtk.vtkXMLUnstructuredGridWriter,
                            "vtu")]:
    data = make()
    for m, c, h in variants:
        write(W(), data, "%s_%s_%s_%d.%s" % (kind, m, c, h, ext), m, c, h)
    write(W(), data, "%s_binary_zlib_64_be.%s" % (kind, ext), "binary",
          "zlib", 64, True)
    write(W(), data, "%s_raw_none_32_be.%s" % (kind, ext), "raw", "none",
          32, True)
    w = W()
    w.SetInputData(data)
    w.SetFileName("%s_default.%s" % (kind, ext))
    assert w.Write() == 1

m = meshio.Mesh(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1],
                          [1, 1, 1.]]),
                [("tetra", np.array([[0, 1, 2, 3], [1, 3, 2, 4]]))],
                point_data={"t": np.arange(5.)},
                cell_data={"r": [np.array([1., 2.])]})
meshio.write("meshio_zlib.vtu", m, binary=True)
meshio.write("meshio_none.vtu", m, binary=True, compression=None)
meshio.write("meshio_lzma.vtu", m, binary=True, compression="lzma")
meshio.write("meshio_ascii.vtu", m, binary=False)
