#!/usr/bin/python3
"""poro-plot - pictures of a run, drawn from its result.h5 alone (schemas/results.md).

    poro-plot RESULT.h5 [--out DIR] [--format png|svg] [--frame N]
    poro-plot element.csv [--case CASE.json] [--out DIR] [--format png|svg]

Writes into DIR (default: the directory of RESULT.h5):
  pore_pressure.FMT   the chosen frame's points coloured by pore pressure (kPa, positive in
                      compression): the water points in double point, the soil points in single
                      point;
  plastic_strain.FMT  the same frame's soil points coloured by accumulated plastic strain;
  probes.FMT          every probe's time series, one panel per unit;
  runout.FMT          for slopes and landslides (bodies that are polygons): the run-out, slide
                      front and crest settlement over time, as `poro-solve report` defines them
                      (docs/report.md), read from the report that command writes;
  terzaghi.FMT        for a one-dimensional consolidation column (one rectangular linear-elastic
                      body loaded on its top by a constant traction, rollers on both sides, no
                      gravity): the pore pressure against depth at every frame, beside Terzaghi's
                      closed form (000 Eqs. 84-86) for the same column.
Given the element.csv of `poro-solve element` instead (docs/element.md), writes element.FMT: q
against p, and q and the volumetric strain against the axial strain, titled from CASE.json when
given. Prints one line per file written. Exit status: 0 on success, 2 for bad arguments or a file that is
not a result, 4 when a file cannot be read or written.

Drawn with matplotlib (Debian's python3-matplotlib) and read with h5py (python3-h5py): pictures with
axes, units and colour bars, made by a plotting library rather than by hand.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

EXIT_INVALID, EXIT_IO = 2, 4

try:
    import h5py
    import matplotlib
    matplotlib.use("Agg")   # files only: no display
    matplotlib.rcParams["svg.fonttype"] = "none"   # SVG text stays text: searchable, editable
    import matplotlib.pyplot as plt
    import numpy as np
except ImportError as e:   # pragma: no cover - deploy/deps.sh installs them
    print("poro-plot: %s (install python3-matplotlib and python3-h5py)" % e, file=sys.stderr)
    sys.exit(EXIT_IO)

VERSION = "1"
G_ACC = 9.81   # the conductivity's gravity (000 Eq. 15), as the solver uses it


def fail(code, message):
    print("poro-plot: " + message, file=sys.stderr)
    sys.exit(code)


def open_result(path):
    if not os.path.exists(path):
        fail(EXIT_IO, "cannot read '%s': no such file" % path)
    try:
        f = h5py.File(path, "r")
    except OSError as e:
        fail(EXIT_INVALID, "'%s' is not a result file: %s" % (path, e))
    if "case" not in f or "frames" not in f or "json" not in f["case"].attrs:
        fail(EXIT_INVALID, "'%s' is not a result file: it has no /case and /frames (schemas/results.md)" % path)
    return f


def frame_names(f):
    """The frames in the order written: the index when the file has one, else the group names."""
    if "frame_names" in f:
        return [n.decode() if isinstance(n, bytes) else str(n) for n in f["frame_names"][:]]
    return sorted(f["frames"])


def save(fig, out_dir, name, fmt):
    path = os.path.join(out_dir, "%s.%s" % (name, fmt))
    try:
        fig.savefig(path, dpi=120, bbox_inches="tight")
    except OSError as e:
        fail(EXIT_IO, "cannot write '%s': %s" % (path, e))
    plt.close(fig)
    print(path)


def points_panel(ax, x, values, label, title, cmap):
    """A scatter of points coloured by values, equal axes in m, with a colour bar."""
    sc = ax.scatter(x[:, 0], x[:, 1], c=values, s=4, cmap=cmap, linewidths=0)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title)
    ax.figure.colorbar(sc, ax=ax, label=label, shrink=0.8)


def figure_for(x):
    """A figure sized to the points' extent, so a tall column and a wide slope both read."""
    span = np.ptp(x, axis=0) if len(x) else np.array([1.0, 1.0])
    aspect = float(span[1] / span[0]) if span[0] > 0 else 1.0
    width = 8.0 if aspect < 1.5 else 4.5
    return plt.subplots(figsize=(width, max(2.5, min(10.0, width * aspect)) + 1.0))


def plot_fields(f, name, out_dir, fmt):
    frame = f["frames"][name]
    t = float(frame.attrs["time"])
    carrier = frame["water"] if "water" in frame else frame["soil"]
    fig, ax = figure_for(carrier["x"][:])
    points_panel(ax, carrier["x"][:], carrier["pore_pressure"][:] / 1e3, "pore pressure (kPa, compression +)",
                 "pore pressure at t = %.6g s (%s points)" % (t, "water" if "water" in frame else "soil"), "viridis")
    save(fig, out_dir, "pore_pressure", fmt)
    soil = frame["soil"]
    fig, ax = figure_for(soil["x"][:])
    points_panel(ax, soil["x"][:], soil["plastic_strain"][:], "accumulated plastic strain (1)",
                 "plastic strain at t = %.6g s" % t, "magma")
    save(fig, out_dir, "plastic_strain", fmt)


def plot_probes(f, out_dir, fmt):
    probes = sorted(f["probes"]) if "probes" in f else []
    if not probes:
        return
    by_unit = {}
    for p in probes:
        unit = f["probes"][p]["value"].attrs.get("units", "")
        by_unit.setdefault(unit.decode() if isinstance(unit, bytes) else unit, []).append(p)
    fig, axes = plt.subplots(len(by_unit), 1, figsize=(8, 3 * len(by_unit)), squeeze=False, sharex=True)
    for ax, (unit, names) in zip(axes[:, 0], sorted(by_unit.items())):
        scale, shown = (1e3, "kPa") if unit == "Pa" else (1e-3, "mm") if unit == "m" else (1.0, unit)
        for p in names:
            ax.plot(f["probes"][p]["time"][:], f["probes"][p]["value"][:] / scale, label=p)
        ax.set_ylabel("value (%s)" % shown)
        ax.legend(fontsize="small")
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("t (s)")
    axes[0, 0].set_title("probes")
    save(fig, out_dir, "probes", fmt)


def plot_runout(result_path, case, out_dir, fmt):
    """Run-out and crest settlement from `poro-solve report` (the definitions of docs/report.md)."""
    if not case.get("bodies") or any("polygon" not in b for b in case["bodies"]):
        return
    solve = os.path.join(os.path.dirname(os.path.abspath(__file__)), "poro-solve")
    with tempfile.TemporaryDirectory() as scratch:
        table = os.path.join(scratch, "report.csv")
        p = subprocess.run([solve, "report", result_path, "--out", table], capture_output=True, text=True)
        if p.returncode != 0:
            print("poro-plot: no run-out picture: %s" % p.stderr.strip(), file=sys.stderr)
            return
        rows = np.genfromtxt(table, delimiter=",", names=True)
    rows = np.atleast_1d(rows)
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    a1.plot(rows["time"], rows["runout"], label="run-out (front of the slope's soil)")
    a1.plot(rows["time"], rows["bulk_front_x"] - rows["bulk_front_x"][0], "--", label="bulk front's run-out (1% of mass ahead)")
    a1.set_ylabel("m")
    a1.legend(fontsize="small")
    a1.grid(alpha=0.3)
    a1.set_title("run-out and crest settlement (docs/report.md)")
    a2.plot(rows["time"], rows["crest_settlement"], color="C2", label="crest settlement")
    a2.set_ylabel("m")
    a2.set_xlabel("t (s)")
    a2.legend(fontsize="small")
    a2.grid(alpha=0.3)
    save(fig, out_dir, "runout", fmt)


def terzaghi_column(case):
    """(H_drainage, height, top, q, c_v, drained_bottom) when the case is a 1-D consolidation column
    (the module docstring), else None."""
    bodies, loads, mats = case.get("bodies", []), case.get("loads", []), case.get("materials", [])
    if len(bodies) != 1 or "rectangle" not in bodies[0] or len(loads) != 1 or len(mats) != 1:
        return None
    m, b, load = mats[0], bodies[0], loads[0]
    g = case.get("gravity", {}).get("acceleration", [0.0, 0.0])
    bc = case.get("boundaries", {})
    sides = all(bc.get(s, {}).get("soil") in ("slip", "fixed") for s in ("left", "right"))
    if (m.get("model") != "linear_elastic" or load.get("face") != "top" or any(g) or not sides or
            load.get("time_function", {}).get("kind") != "constant" or load.get("traction", [0, 0])[0] != 0.0):
        return None
    E, nu = m["youngs_modulus"], m.get("poisson_ratio", 0.0)
    M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    k = b["hydraulic_conductivity"]
    rho_w = case.get("fluid", {}).get("density", 1000.0)
    bottom, top = b["rectangle"]["min"][1], b["rectangle"]["max"][1]
    drained_bottom = bc.get("bottom", {}).get("water", "free") == "free"
    height = top - bottom
    H = height / 2 if drained_bottom else height
    return H, height, top, -load["traction"][1], k * M / (rho_w * G_ACC), drained_bottom


def terzaghi_pressure(z, H, tv, terms=200):
    """p / q at distance z from a drained face, drainage length H, time factor tv (000 Eq. 84)."""
    s = 0.0
    for m in range(terms):
        Mm = (2 * m + 1) * math.pi / 2
        s += 2 / Mm * math.sin(Mm * z / H) * math.exp(-Mm * Mm * tv)
    return s


def plot_terzaghi(f, case, out_dir, fmt):
    col = terzaghi_column(case)
    if not col:
        return
    H, height, top, q, cv, drained_bottom = col
    fig, ax = plt.subplots(figsize=(6, 6))
    for i, name in enumerate(frame_names(f)):
        frame = f["frames"][name]
        t = float(frame.attrs["time"])
        if t <= 0:
            continue
        carrier = frame["water"] if "water" in frame else frame["soil"]
        x0 = carrier["x"][:] - carrier["displacement"][:]
        depth = top - x0[:, 1]
        colour = "C%d" % (i % 10)
        tv = cv * t / (H * H)
        ax.plot(carrier["pore_pressure"][:] / q, depth, ".", ms=2, color=colour, alpha=0.5)
        zs = np.linspace(0.0, height, 101)
        dist = np.minimum(zs, height - zs) if drained_bottom else zs   # to the nearest drained face
        ax.plot([terzaghi_pressure(d, H, tv) for d in dist], zs, "-", color=colour, lw=1,
                label="Tv = %.3g" % tv)
    ax.invert_yaxis()
    ax.set_xlabel("p / q")
    ax.set_ylabel("depth below the loaded top, reference (m)")
    ax.set_title("Terzaghi: points (dots) against the closed form (lines)")
    ax.legend(fontsize="x-small", ncol=2)
    ax.grid(alpha=0.3)
    save(fig, out_dir, "terzaghi", fmt)


def plot_element(csv_path, case_path, out_dir, fmt):
    """The single-element test's curves from element.csv (docs/element.md)."""
    try:
        rows = np.genfromtxt(csv_path, delimiter=",", names=True)
    except (OSError, ValueError) as e:
        fail(EXIT_IO if isinstance(e, OSError) else EXIT_INVALID, "cannot read '%s': %s" % (csv_path, e))
    need = ("axial_strain", "p", "q", "volumetric_strain")
    if rows.dtype.names is None or any(n not in rows.dtype.names for n in need) or rows.size < 2:
        fail(EXIT_INVALID, "'%s' is not an element.csv: it needs a header with %s and two rows or more" %
             (csv_path, ", ".join(need)))
    title = "single element"
    if case_path:
        try:
            case = json.load(open(case_path))
        except (OSError, ValueError) as e:
            fail(EXIT_INVALID, "cannot read the case '%s': %s" % (case_path, e))
        title = "%s (%s triaxial, confining pressure %g kPa)" % (case.get("title", title), case.get("test", "?"),
                                                                   case.get("confining_pressure", float("nan")) / 1e3)
    ea = rows["axial_strain"] * 100
    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(14, 4.2))
    a1.plot(rows["p"] / 1e3, rows["q"] / 1e3)
    a1.set_xlabel("p, mean effective stress (kPa)")
    a1.set_ylabel("q, deviator stress (kPa)")
    a1.set_title("q against p")
    a2.plot(ea, rows["q"] / 1e3)
    a2.set_xlabel("axial strain (%, negative = compression)")
    a2.set_ylabel("q, deviator stress (kPa)")
    a2.set_title("q against axial strain")
    a3.plot(ea, rows["volumetric_strain"] * 100)
    a3.set_xlabel("axial strain (%, negative = compression)")
    a3.set_ylabel("volumetric strain (%, negative = contraction)")
    a3.set_title("volumetric strain")
    for a in (a1, a2, a3):
        a.grid(alpha=0.3)
    fig.suptitle(title)
    fig.tight_layout()
    save(fig, out_dir, "element", fmt)


def main(argv):
    ap = argparse.ArgumentParser(prog="poro-plot", description="Pictures of a run from its result.h5.",
                                 epilog="Files written: pore_pressure, plastic_strain, probes, and where the case "
                                        "allows runout and terzaghi (see the head of this script).")
    ap.add_argument("result", help="the run's result.h5, or the element.csv of `poro-solve element`")
    ap.add_argument("--case", help="element.csv only: the element case, for the picture's title")
    ap.add_argument("--out", help="directory to write into (default: the result's own)")
    ap.add_argument("--format", choices=("png", "svg"), default="png")
    ap.add_argument("--frame", type=int, help="the frame of the field pictures, counted from 0 (default: the last)")
    ap.add_argument("--version", action="version", version="poro-plot " + VERSION)
    try:
        args = ap.parse_args(argv)
    except SystemExit as e:
        return EXIT_INVALID if e.code else 0
    out_dir = args.out or os.path.dirname(os.path.abspath(args.result))
    if not os.path.isdir(out_dir):
        fail(EXIT_IO, "cannot write into '%s': not a directory" % out_dir)
    if args.result.endswith(".csv"):
        plot_element(args.result, args.case, out_dir, args.format)
        return 0
    f = open_result(args.result)
    try:
        case = json.loads(f["case"].attrs["json"])
    except ValueError as e:
        fail(EXIT_INVALID, "'%s': its /case json does not parse: %s" % (args.result, e))
    names = frame_names(f)
    if not names:
        fail(EXIT_INVALID, "'%s' has no frames" % args.result)
    which = len(names) - 1 if args.frame is None else args.frame
    if not 0 <= which < len(names):
        fail(EXIT_INVALID, "--frame %d: the file has frames 0 to %d" % (which, len(names) - 1))
    plot_fields(f, names[which], out_dir, args.format)
    plot_probes(f, out_dir, args.format)
    plot_runout(args.result, case, out_dir, args.format)
    plot_terzaghi(f, case, out_dir, args.format)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
