#!/usr/bin/python3
"""Reads a .vtp file with VTK's own XML reader (Debian's python3-vtk9) and prints, as JSON,
what ParaView would see of it: points, vertex cells, and each point array's name, components
and range. Used by tests/export_test.cpp."""
import json
import sys

from vtkmodules.vtkIOXML import vtkXMLPolyDataReader

def data_missing(r):
    return r.GetOutput() is None or r.GetNumberOfPoints() == 0


reader = vtkXMLPolyDataReader()
reader.SetFileName(sys.argv[1])
reader.Update()
if data_missing(reader):
    sys.exit(f"vtk could not read {sys.argv[1]}")
data = reader.GetOutput()
arrays = {}
for k in range(data.GetPointData().GetNumberOfArrays()):
    a = data.GetPointData().GetArray(k)
    per_component = [list(a.GetRange(c)) for c in range(a.GetNumberOfComponents())]
    arrays[a.GetName()] = {"components": a.GetNumberOfComponents(), "tuples": a.GetNumberOfTuples(),
                           "range": per_component}
print(json.dumps({"points": data.GetNumberOfPoints(), "verts": data.GetNumberOfVerts(),
                  "cells": data.GetNumberOfCells(), "arrays": arrays}))
