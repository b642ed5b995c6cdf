"""Reads particle frames with meshio (a third-party VTK reader) and prints what it found as JSON.

    read_vtu.py FRAME.vtu       -> {"time", "points", "cells", "point_data", "field_data"}
    read_vtu.py SERIES.pvd      -> a list of those, one per data set of the ParaView collection, with its
                                   "timestep" and "file" (the .pvd is read with the standard XML parser)

Arrays are printed in full, as lists (float32 values as the nearest float64).
"""
import json
import os
import sys
import xml.etree.ElementTree as ET

import meshio


def frame(path):
    m = meshio.read(path)
    cells = {}
    for block in m.cells:
        cells[block.type] = cells.get(block.type, 0) + len(block.data)
    return {
        "points": m.points.tolist(),
        "cells": cells,
        # A one-component array (NumberOfComponents="1") reads as n x 1: printed as a flat list.
        "point_data": {
            k: (v[:, 0] if v.ndim == 2 and v.shape[1] == 1 else v).tolist()
            for k, v in m.point_data.items()
        },
        "dtypes": {k: str(v.dtype) for k, v in m.point_data.items()},
        "field_data": {k: v.tolist() for k, v in m.field_data.items()},
    }


def main(path):
    if path.endswith(".pvd"):
        root = ET.parse(path).getroot()
        assert root.get("type") == "Collection", root.get("type")
        out = []
        for ds in root.iter("DataSet"):
            f = frame(os.path.join(os.path.dirname(path), ds.get("file")))
            f["timestep"] = float(ds.get("timestep"))
            f["file"] = ds.get("file")
            out.append(f)
        return out
    return frame(path)


if __name__ == "__main__":
    json.dump(main(sys.argv[1]), sys.stdout)
