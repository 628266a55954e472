"""Reads result.xdmf with ParaView's XDMF readers and prints, per reader and frame, the frame's time,
and each block's name, point count and point arrays, as one JSON object on stdout.
Usage: python3 xdmf_read.py RESULT.xdmf   (Debian's python3-paraview; /usr/bin/python3)."""
import json
import sys

from paraview import servermanager
from paraview.simple import XDMFReader, Xdmf3ReaderT


def arrays_of(block):
    data = block.GetPointData()
    return sorted(data.GetArrayName(k) for k in range(data.GetNumberOfArrays()))


def blocks(data):
    """(name, points, arrays) of every leaf block of a multiblock, in order; a lone dataset (one
    point set, which Xdmf3 Reader T hands out without a multiblock around it) is one unnamed block."""
    if not data.IsA("vtkMultiBlockDataSet"):
        return [{"name": None, "points": data.GetNumberOfPoints(), "arrays": arrays_of(data)}]
    out = []
    for i in range(data.GetNumberOfBlocks()):
        meta = data.GetMetaData(i)
        name = meta.Get(data.NAME()) if meta.Has(data.NAME()) else None
        block = data.GetBlock(i)
        if block is None:
            continue
        if block.IsA("vtkMultiBlockDataSet"):
            out.extend(blocks(block))
            continue
        out.append({"name": name, "points": block.GetNumberOfPoints(), "arrays": arrays_of(block)})
    return out


def read(reader):
    frames = []
    for t in list(reader.TimestepValues or []):
        reader.UpdatePipeline(t)
        frames.append({"time": t, "blocks": blocks(servermanager.Fetch(reader))})
    return frames


path = sys.argv[1]
print(json.dumps({"xdmf2": read(XDMFReader(FileNames=[path])), "xdmf3": read(Xdmf3ReaderT(FileName=path))}))
