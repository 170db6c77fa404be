"""What ParaView's XDMF reader sees in a run's output: per file its points, cells, time steps (count, first, last)
and the point arrays with their components and magnitude range at the last time step, as one JSON line (the
check of runs/seismic/README.md's oblique site; any petsc-ssi .xmf).

    xvfb-run -a pvpython jobscripts/pv_read.py OUT.xmf [OUT_structure.xmf ...]     (apt-get install paraview xvfb)
"""
import json
import os
import sys

from paraview import servermanager as sm
from paraview.simple import UpdatePipeline, XDMFReader


def read(fn):
    r = XDMFReader(FileNames=[fn])
    ts = list(r.TimestepValues) if r.TimestepValues else []
    UpdatePipeline(time=ts[-1] if ts else 0.0, proxy=r)
    d = sm.Fetch(r)
    if not hasattr(d, "GetPointData"):          # (a multiblock: its first block)
        d = d.GetBlock(0)
    pd = d.GetPointData()
    arrays = {}
    for i in range(pd.GetNumberOfArrays()):
        a = pd.GetArray(i)
        arrays[a.GetName()] = {"components": a.GetNumberOfComponents(), "magnitude_range": list(a.GetRange(-1))}
    return {"points": d.GetNumberOfPoints(), "cells": d.GetNumberOfCells(),
            "time_steps": len(ts), "t_first_s": ts[0] if ts else None, "t_last_s": ts[-1] if ts else None,
            "point_arrays_at_t_last": arrays}


if __name__ == "__main__":
    print(json.dumps({os.path.basename(f): read(f) for f in sys.argv[1:]}))
