#!/usr/bin/python3
"""Plot one simulator run like the paper's figures 2 to 4.

    scripts/plot_run.py RUNDIR [--outdir DIR]

RUNDIR is an `rfseek-sim --out` directory (summary.json, track.tsv, log.tsv, samples.tsv,
and field.tsv when run with --field). Writes into DIR (default RUNDIR):
  trajectory.png  the map, the trajectory, the start (red cross), the source (red star)
                  and the model updates (red circles)                  (paper figs. 3, 4 top)
  rssi.png        RSSI of every received packet against the distance travelled, with its
                  moving average over 1 m                               (paper figs. 3, 4 bottom)
  hexbin.png      hexagonal histogram of the simulated field: mean RSSI per hexagon of
                  about 0.6 m (larger than the wavelength, as the paper's) (paper fig. 2)
  residual.png    with residual.tsv (--model pathloss): the path-loss fit's RMS
                  residual over the coarse candidate source positions as a heat map on the
                  map, with the true source (red star), the final estimate (white cross),
                  its uncertainty area and the trajectory
Images are written to a temporary name and renamed.
"""
import json
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def die(msg):
    print("plot_run.py: %s" % msg, file=sys.stderr)
    sys.exit(1)


def read_map(yaml_path):
    """The map image (row 0 = top, as in the PGM) and its extent in metres."""
    meta = {}
    with open(yaml_path) as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if ":" in line:
                k, v = line.split(":", 1)
                meta[k.strip()] = v.strip()
    img = os.path.join(os.path.dirname(yaml_path), meta["image"])
    res = float(meta["resolution"])
    ox, oy = [float(v) for v in meta["origin"].strip("[]").split(",")[:2]]
    with open(img, "rb") as f:
        data = f.read()
    m = re.match(rb"P5\s+(?:#[^\n]*\n\s*)*(\d+)\s+(\d+)\s+(\d+)\s", data)
    if not m:
        die("%s: not a binary PGM" % img)
    w, h = int(m.group(1)), int(m.group(2))
    a = np.frombuffer(data[m.end():m.end() + w * h], dtype=np.uint8).reshape(h, w)
    return a, [ox, ox + w * res, oy, oy + h * res]


def read_tsv(path):
    with open(path) as f:
        head = f.readline().rstrip("\n").split("\t")
        rows = [line.rstrip("\n").split("\t") for line in f if line.strip()]
    return head, rows


def col(head, rows, name, conv=float):
    i = head.index(name)
    return np.array([conv(r[i]) if r[i] != "" else np.nan for r in rows])


def save(fig, path):
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=110, bbox_inches="tight")
    plt.close(fig)
    os.replace(tmp, path)


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(argv) >= 2 else 1
    run = argv[1]
    outdir = argv[3] if len(argv) == 4 and argv[2] == "--outdir" else run
    try:
        with open(os.path.join(run, "summary.json")) as f:
            s = json.load(f)
    except (OSError, ValueError) as e:
        die("%s: %s" % (run, e))
    img, ext = read_map(s["map"])
    sources = np.array(s["sources"])
    start = s["start"]

    # Trajectory with start, source and model updates.
    th, tr = read_tsv(os.path.join(run, "track.tsv"))
    lh, lr = read_tsv(os.path.join(run, "log.tsv"))
    x, y = col(th, tr, "x_m"), col(th, tr, "y_m")
    relearn = col(lh, lr, "relearned", int) == 1
    ux, uy = col(lh, lr, "x_m")[relearn], col(lh, lr, "y_m")[relearn]
    fig, ax = plt.subplots(figsize=(10, 10 * (ext[3] - ext[2]) / (ext[1] - ext[0]) + 1))
    ax.imshow(img, cmap="gray", extent=ext, vmin=0, vmax=255)
    ax.plot(x, y, "-", color="tab:blue", lw=1.2, label="trajectory")
    ax.plot(ux, uy, "o", mfc="none", mec="red", ms=7, label="model updates (%d)" % relearn.sum())
    # Wall contacts: where the robot began touching a wall (track.tsv's touching column).
    touch = col(th, tr, "touching", int) == 1
    began = touch & ~np.concatenate(([False], touch[:-1]))
    ax.plot(x[began], y[began], "s", mfc="none", mec="orange", ms=9, mew=2,
            label="wall contacts (%s)" % s.get("wall_contacts", int(began.sum())))
    ax.plot(start[0], start[1], "x", color="red", ms=12, mew=3, label="start")
    ax.plot(sources[:, 0], sources[:, 1], "*", color="red", ms=18, label="source")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("%s, seed %d: %s after %.1f m (shortest path %s m)" % (
        os.path.basename(s["scenario"]), s["seed"],
        "reached" if s["reached"] else "not reached (%s)" % s["end"],
        s["distance_travelled_m"],
        "%.1f" % s["shortest_path_m"] if s["shortest_path_m"] is not None else "-"))
    ax.legend(loc="upper left", fontsize=8)
    save(fig, os.path.join(outdir, "trajectory.png"))

    # RSSI against distance travelled with the 1 m moving average.
    sp = os.path.join(run, "samples.tsv")
    if os.path.exists(sp):
        sh, sr = read_tsv(sp)
        d, v, src = col(sh, sr, "travelled_m"), col(sh, sr, "dbm"), col(sh, sr, "src", int)
        fig, ax = plt.subplots(figsize=(10, 4))
        for k in sorted(set(src.tolist())):
            sel = src == k
            dk, vk = d[sel], v[sel]
            ax.plot(dk, vk, ".", ms=1, alpha=0.25, color="C%d" % k,
                    label="RSSI source %d" % k)
            # Mean over the trailing metre of travel at each packet (cumulative sums).
            c = np.concatenate([[0.0], np.cumsum(vk)])
            lo = np.searchsorted(dk, dk - 1.0, side="right")
            hi = np.arange(1, len(dk) + 1)
            ax.plot(dk, (c[hi] - c[lo]) / (hi - lo), "-", color="black" if k == 0 else "C3",
                    lw=1.3, label="1 m moving average, source %d" % k)
        ax.set_xlabel("distance travelled [m]")
        ax.set_ylabel("RSSI [dBm]")
        ax.legend(loc="lower right", fontsize=8)
        save(fig, os.path.join(outdir, "rssi.png"))

    # Hexbin of the simulated field (one packet per free 0.1 m cell).
    fp = os.path.join(run, "field.tsv")
    if os.path.exists(fp):
        fh, fr = read_tsv(fp)
        fx, fy, fv = col(fh, fr, "x_m"), col(fh, fr, "y_m"), col(fh, fr, "dbm")
        ok = ~np.isnan(fv)
        fig, ax = plt.subplots(figsize=(10, 10 * (ext[3] - ext[2]) / (ext[1] - ext[0]) + 1))
        ax.imshow(img, cmap="gray", extent=ext, vmin=0, vmax=255, alpha=0.5)
        hb = ax.hexbin(fx[ok], fy[ok], C=fv[ok], reduce_C_function=np.mean,
                       gridsize=int((ext[1] - ext[0]) / 0.6), cmap="viridis", mincnt=3)
        fig.colorbar(hb, ax=ax, label="mean RSSI [dBm]", shrink=0.7)
        ax.plot(sources[:, 0], sources[:, 1], "*", color="red", ms=18)
        ax.set_title("simulated field: %d packets (%d lost)" % (ok.sum(), (~ok).sum()))
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        save(fig, os.path.join(outdir, "hexbin.png"))

    rp = os.path.join(run, "residual.tsv")
    if os.path.exists(rp):
        plot_residual(rp, s, img, ext, sources, x, y, os.path.join(outdir, "residual.png"))
    return 0


def plot_residual(path, s, img, ext, sources, tx, ty, out):
    """Heat map of residual.tsv (one value per coarse candidate on a regular lattice)."""
    rh, rr = read_tsv(path)
    if not rr:
        return  # no fit: nothing to draw
    try:
        rx, ry, rv = col(rh, rr, "x_m"), col(rh, rr, "y_m"), col(rh, rr, "residual_db")
    except (ValueError, IndexError) as e:
        die("%s: %s" % (path, e))
    xs, ys = np.unique(rx), np.unique(ry)
    dx = np.min(np.diff(xs)) if len(xs) > 1 else 1.0
    dy = np.min(np.diff(ys)) if len(ys) > 1 else dx
    nx, ny = int(round((xs[-1] - xs[0]) / dx)) + 1, int(round((ys[-1] - ys[0]) / dy)) + 1
    grid = np.full((ny, nx), np.nan)
    grid[np.rint((ry - ys[0]) / dy).astype(int), np.rint((rx - xs[0]) / dx).astype(int)] = rv
    fig, ax = plt.subplots(figsize=(10, 10 * (ext[3] - ext[2]) / (ext[1] - ext[0]) + 1))
    ax.imshow(img, cmap="gray", extent=ext, vmin=0, vmax=255)
    # Cells centred on the candidates; illegal points stay transparent.
    pc = ax.imshow(np.ma.masked_invalid(grid), origin="lower", cmap="magma_r", alpha=0.75,
                   extent=[xs[0] - dx / 2, xs[0] + (nx - 0.5) * dx,
                           ys[0] - dy / 2, ys[0] + (ny - 0.5) * dy],
                   interpolation="nearest")
    fig.colorbar(pc, ax=ax, label="RMS residual of the fit [dB]", shrink=0.7)
    # Walls again on top so the rooms stay visible through the heat map.
    ax.imshow(np.ma.masked_where(img > 100, img), cmap="gray", extent=ext, vmin=0, vmax=255)
    ax.plot(tx, ty, "-", color="tab:cyan", lw=1.0, label="trajectory")
    ax.plot(sources[:, 0], sources[:, 1], "*", color="red", ms=18, label="source")
    title = "path-loss residual surface (%d candidates, best %.2f dB)" % (len(rv), np.min(rv))
    if s.get("est_src_x_m") is not None:
        ax.plot(s["est_src_x_m"], s["est_src_y_m"], "P", color="white", mec="black", ms=14,
                label="estimate (n %.2f, W %.1f dB)" % (s["est_n"], s["est_w_db"]))
        # The uncertainty area drawn as a circle of the same area.
        ax.add_patch(plt.Circle((s["est_src_x_m"], s["est_src_y_m"]),
                                np.sqrt(s["est_area_m2"] / np.pi), fill=False, ec="white",
                                ls="--", lw=1.2, label="uncertainty %.0f m^2" % s["est_area_m2"]))
        title += ", error %.2f m" % s["est_error_m"]
    ax.set_xlim(ext[0], ext[1])
    ax.set_ylim(ext[2], ext[3])
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title)
    ax.legend(loc="upper left", fontsize=8)
    save(fig, out)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
