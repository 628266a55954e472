#!/usr/bin/python3
# frame_values.py RESULT.h5 [PROBE] - (Debian's python3, where python3-h5py installs) values of a
# run as it wrote them, read with h5py from result.h5 itself, for the dashboard test to compare
# its plots against, as JSON on stdout:
#   without PROBE: the last frame's pore-pressure carriers (the water points in double point, the
#                  soil points in single point), {"time", "y", "p"};
#   with PROBE:    that probe's series, {"time", "value"}.
import json
import sys

import h5py

with h5py.File(sys.argv[1], "r") as f:
    if len(sys.argv) > 2:
        probe = f["probes"][sys.argv[2]]
        json.dump({"time": probe["time"][:].tolist(), "value": probe["value"][:].tolist()}, sys.stdout)
        sys.exit(0)
    names = [n.decode() for n in f["frame_names"][:]]
    frame = f["frames"][names[-1]]
    points = frame["water"] if "water" in frame else frame["soil"]
    json.dump({"time": float(frame.attrs["time"]), "y": points["x"][:, 1].tolist(),
               "p": points["pore_pressure"][:].tolist()}, sys.stdout)
