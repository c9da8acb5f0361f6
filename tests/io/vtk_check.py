#!/usr/bin/python3
"""Opens a swirl .pvd series with VTK's own XML reader (the one ParaView uses).

Usage: vtk_check.py OUT_DIR/particles.pvd [OUT_DIR/boundary.pvd ...]
Checks that every frame listed in the .pvd loads without a VTK error or
warning, has the same number of points, one vertex cell per point, the named
arrays swirl writes with the right number of components, finite values, every
other point array (a solver's fields, real or integer) with one tuple per
point and integer fields as VTK integer arrays, and a TimeValue equal to the
time in the .pvd. Needs Debian's python3-vtk9.
"""
import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import vtk
from vtk.util.numpy_support import vtk_to_numpy

EXPECTED = {"velocity": 3, "acceleration": 3, "acceleration_prev": 3, "mass": 1,
            "density": 1, "pressure": 1, "id": 1}


class ErrorCatcher:
    def __init__(self):
        self.messages = []

    def __call__(self, obj, event):
        self.messages.append(f"{event} from {obj.GetClassName()}")


def main(pvd: Path) -> int:
    entries = [(float(d.get("timestep")), d.get("file")) for d in ET.parse(pvd).getroot().iter("DataSet")]
    if not entries:
        print(f"{pvd}: no frames", file=sys.stderr)
        return 1
    count = None
    for time, name in entries:
        reader = vtk.vtkXMLPolyDataReader()
        catcher = ErrorCatcher()
        reader.AddObserver("ErrorEvent", catcher)
        reader.AddObserver("WarningEvent", catcher)
        reader.SetFileName(str(pvd.parent / name))
        reader.Update()
        poly = reader.GetOutput()
        problems = list(catcher.messages)
        n = poly.GetNumberOfPoints()
        if count is None:
            count = n
        if n == 0 or n != count:
            problems.append(f"{n} points (first frame had {count})")
        if poly.GetNumberOfVerts() != n:
            problems.append(f"{poly.GetNumberOfVerts()} vertex cells for {n} points")
        pd = poly.GetPointData()
        for array, components in EXPECTED.items():
            a = pd.GetArray(array)
            if a is None:
                problems.append(f"array '{array}' missing")
            elif a.GetNumberOfComponents() != components or a.GetNumberOfTuples() != n:
                problems.append(f"array '{array}' has shape {a.GetNumberOfTuples()}x{a.GetNumberOfComponents()}")
            elif array != "id" and not all(math.isfinite(v) for v in vtk_to_numpy(a).ravel()):
                problems.append(f"array '{array}' has non-finite values")
        for k in range(pd.GetNumberOfArrays()):
            a = pd.GetArray(k)
            if a.GetName() in EXPECTED:
                continue
            if a.GetNumberOfTuples() != n:
                problems.append(f"array '{a.GetName()}' has {a.GetNumberOfTuples()} tuples for {n} points")
            if a.IsA("vtkDataArray") and a.GetDataType() not in (vtk.VTK_FLOAT, vtk.VTK_DOUBLE, vtk.VTK_INT):
                problems.append(f"array '{a.GetName()}' has type {a.GetDataTypeAsString()} "
                                "(swirl writes Float32, Float64 or Int32)")
        ids = vtk_to_numpy(pd.GetArray("id")) if pd.GetArray("id") is not None else []
        # A run's ids are 0..N-1 over its two series (particles.pvd and
        # boundary.pvd): within one frame, distinct.
        if len(ids) and len(set(ids.tolist())) != n:
            problems.append("ids are not distinct")
        tv = poly.GetFieldData().GetArray("TimeValue")
        if tv is None or tv.GetValue(0) != time:
            problems.append(f"TimeValue {tv.GetValue(0) if tv else None} != {time} in the .pvd")
        if problems:
            print(f"{name}: " + "; ".join(problems), file=sys.stderr)
            return 1
    print(f"{pvd}: {len(entries)} frames of {count} points read by VTK {vtk.vtkVersion.GetVTKVersion()}: OK")
    return 0


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    sys.exit(max([main(Path(a)) for a in sys.argv[1:]]))
