#!/usr/bin/python3
# frame_values.py RESULT.h5 - (Debian's python3, where python3-h5py installs) the last frame's pore-pressure carriers as the run wrote them (the
# water points in double point, the soil points in single point): {"time", "y", "p"} on stdout,
# read with h5py from result.h5 itself, for the dashboard test to compare its plot against.
import json
import sys

import h5py

with h5py.File(sys.argv[1], "r") as f:
    names = [n.decode() for n in f["frame_names"][:]]
    frame = f["frames"][names[-1]]
    points = frame["water"] if "water" in frame else frame["soil"]
    json.dump({"time": float(frame.attrs["time"]), "y": points["x"][:, 1].tolist(),
               "p": points["pore_pressure"][:].tolist()}, sys.stdout)
