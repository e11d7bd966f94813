#!/usr/bin/python3
"""Plot one simulator run like the paper's figures 2 to 4.

    scripts/plot_run.py RUNDIR [--outdir DIR]
    scripts/plot_run.py RUNDIR --animate [--out FILE] [--fps N] [--speed S] [--max-frames N]

RUNDIR is an `rfseek-sim --out` directory (summary.json, track.tsv, log.tsv, samples.tsv,
and field.tsv when run with --field). Writes into DIR (default RUNDIR; made if missing):
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

--animate writes a video of the run instead (default RUNDIR/run.gif): the map, the
trajectory so far, the robot (an orange disc of radius 0.177 m with a heading tick, at the
last track.tsv row not after the frame's time, or the first), the packets so far coloured
by dBm (every k-th when there are more than 20,000), the goal of the current decision
(green x), the path-loss source estimate with its uncertainty area when log.tsv has one
(white plus), the true source (red star) and "t = 12 s, travelled 3.4 m" (along
track.tsv). Frames are taken every S/N seconds of simulated time (--speed S simulated
seconds per video second, default 10; --fps N frames per second, 1..60, default 10) from
0 to the last track row, which gets the last frame; with more than --max-frames (default
600) they are spread evenly instead. A frame is 960 pixels wide; the map is drawn 40 px
from the left and 36 px from the top at the largest scale that fits 840 x 720 px, then 56
px below it (the height rounded up to even). FILE ending in .mp4 is encoded by ffmpeg
(H.264), anything else is a GIF (Pillow).
"""
import json
import os
import re
import shutil
import subprocess
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
        return read_image_pil(img, meta.get("negate", "0").strip() == "1", res, ox, oy)
    w, h = int(m.group(1)), int(m.group(2))
    a = np.frombuffer(data[m.end():m.end() + w * h], dtype=np.uint8).reshape(h, w)
    return a, [ox, ox + w * res, oy, oy + h * res]


def read_image_pil(img, negate, res, ox, oy):
    """A map image that is not a binary PGM (PNG, ASCII PGM) read with Pillow as gray levels
    for display (negate: dark is free); its extent as read_map's."""
    try:
        from PIL import Image
        with Image.open(img) as im:
            a = np.asarray(im.convert("L"), dtype=np.uint8)
    except (ImportError, OSError) as e:
        die("%s: %s" % (img, e))
    if negate:
        a = 255 - a
    h, w = a.shape
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
    if "--animate" in argv[2:]:
        return animate_main(run, argv[2:])
    if len(argv) == 2:
        outdir = run
    elif len(argv) == 4 and argv[2] == "--outdir":
        outdir = argv[3]
    else:
        die("expected RUNDIR [--outdir DIR] or RUNDIR --animate [...], got %r (see --help)"
            % " ".join(argv[2:]))
    try:
        with open(os.path.join(run, "summary.json")) as f:
            s = json.load(f)
    except (OSError, ValueError) as e:
        die("%s: %s" % (run, e))
    try:
        img, ext = read_map(s["map"])
    except (OSError, KeyError, ValueError) as e:
        die("map %s: %s (summary.json's paths are relative to where rfseek-sim ran)"
            % (s["map"], e.strerror if isinstance(e, OSError) else "bad YAML: %s" % e))
    sources = np.array(s["sources"])
    start = s["start"]
    try:
        os.makedirs(outdir, exist_ok=True)
    except OSError as e:
        die("--outdir %s: %s" % (outdir, e.strerror))

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
    """Heat map of residual.tsv: one value per coarse candidate, drawn as its cell of the
    regular coarse grid (cell_x_m, cell_y_m; files without them: the candidates' own x, y)."""
    rh, rr = read_tsv(path)
    if not rr:
        return  # no fit: nothing to draw
    try:
        cells = "cell_x_m" in rh and "cell_y_m" in rh
        rx = col(rh, rr, "cell_x_m" if cells else "x_m")
        ry = col(rh, rr, "cell_y_m" if cells else "y_m")
        rv = col(rh, rr, "residual_db")
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


# --animate: frame layout in pixels (documented in the module docstring; the test
# tests/host_sim/animate_test.py computes robot positions from it).
ANIM_W, ANIM_LEFT, ANIM_TOP, ANIM_BOTTOM, ANIM_RIGHT, ANIM_MAX_H = 960, 40, 36, 56, 80, 720
ROBOT_RADIUS_M = 0.177  # the simulated robot's body (docs/SIMULATOR.md)
ROBOT_RGB = (1.0, 0.5, 0.0)
ANIM_MAX_SAMPLES = 20000


def anim_option(opts, name, conv, lo, hi, default):
    """The value of --name in opts (conv'd, within [lo, hi]) or default; one-line error."""
    if name not in opts:
        return default
    v = opts[name]
    try:
        x = conv(v)
        if not lo <= x <= hi or x != x:
            raise ValueError
    except ValueError:
        die("%s: expected a number in [%g, %g], got %s" % (name, lo, hi, v.replace("\n", "?")))
    return x


def anim_frame_times(t_end, fps, speed, max_frames):
    """Frame times: every speed/fps simulated seconds from 0, the last one at t_end; spread
    evenly over [0, t_end] when that would be more than max_frames."""
    dt = speed / fps
    n = int(np.ceil(t_end / dt - 1e-9)) + 1 if t_end > 0 else 1
    if n > max_frames:
        return np.linspace(0.0, t_end, max_frames)
    t = np.arange(n) * dt
    t[-1] = t_end
    return t


def animate_main(run, args):
    opts, i = {}, 0
    while i < len(args):
        a = args[i]
        if a == "--animate":
            i += 1
            continue
        if a not in ("--out", "--fps", "--speed", "--max-frames") or i + 1 >= len(args):
            die("%s: unknown option or missing value (see --help)" % a.replace("\n", "?"))
        opts[a] = args[i + 1]
        i += 2
    fps = anim_option(opts, "--fps", float, 1, 60, 10.0)
    speed = anim_option(opts, "--speed", float, 1e-3, 1e6, 10.0)
    max_frames = anim_option(opts, "--max-frames", int, 2, 100000, 600)
    out = opts.get("--out", os.path.join(run, "run.gif"))
    mp4 = out.lower().endswith(".mp4")
    if mp4 and shutil.which("ffmpeg") is None:
        die("%s: an MP4 needs ffmpeg (apt-get install ffmpeg), or name a .gif" % out)
    try:
        with open(os.path.join(run, "summary.json")) as f:
            s = json.load(f)
        img, ext = read_map(s["map"])
        th, tr = read_tsv(os.path.join(run, "track.tsv"))
        lh, lr = read_tsv(os.path.join(run, "log.tsv"))
        tt, tx, ty, tth = (col(th, tr, k) for k in ("t_s", "x_m", "y_m", "theta_rad"))
        lt, gx, gy = (col(lh, lr, k) for k in ("t_s", "goal_x_m", "goal_y_m"))
        ex, ey, ea = ((col(lh, lr, k) for k in ("est_src_x_m", "est_src_y_m", "est_area_m2"))
                      if "est_src_x_m" in lh else (np.full(len(lr), np.nan),) * 3)
        sp = os.path.join(run, "samples.tsv")
        sh, sr = read_tsv(sp) if os.path.exists(sp) else (["t_s", "x_m", "y_m", "dbm"], [])
        st, sx, sy, sv = (col(sh, sr, k) for k in ("t_s", "x_m", "y_m", "dbm"))
    except (OSError, ValueError, KeyError, IndexError, TypeError) as e:
        die("%s: %s" % (run, str(e).replace("\n", " ")))
    if len(tt) == 0 or not np.all(np.isfinite(tt)) or np.any(np.diff(tt) < 0):
        die("%s: track.tsv: no rows or times not increasing" % run)
    times = anim_frame_times(tt[-1], fps, speed, max_frames)
    k = max(1, -(-len(st) // ANIM_MAX_SAMPLES))
    st, sx, sy, sv = st[::k], sx[::k], sy[::k], sv[::k]
    travelled = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(tx), np.diff(ty)))])

    # Layout: the map at scale px_m pixels per metre, placed exactly in pixels.
    mw, mh = ext[1] - ext[0], ext[3] - ext[2]
    px_m = min((ANIM_W - ANIM_LEFT - ANIM_RIGHT) / mw, ANIM_MAX_H / mh)
    aw, ah = mw * px_m, mh * px_m
    hgt = ANIM_TOP + int(np.ceil(ah - 1e-6)) + ANIM_BOTTOM
    hgt += hgt % 2
    fig = plt.figure(figsize=(ANIM_W / 100, hgt / 100), dpi=100)
    ax = fig.add_axes([ANIM_LEFT / ANIM_W, (hgt - ANIM_TOP - ah) / hgt, aw / ANIM_W, ah / hgt])
    ax.imshow(img, cmap="gray", extent=ext, vmin=0, vmax=255, aspect="auto",
              interpolation="nearest")
    ax.set_xlim(ext[0], ext[1])
    ax.set_ylim(ext[2], ext[3])
    ax.tick_params(labelsize=7)
    finite = sv[np.isfinite(sv)]
    lo, hi = (np.percentile(finite, [2, 98]) if len(finite) else (-90.0, -30.0))
    sc = ax.scatter(sx[:0], sy[:0], c=sv[:0], s=7, cmap="viridis", vmin=lo, vmax=hi,
                    linewidths=0, zorder=3)
    cax = fig.add_axes([(ANIM_LEFT + aw + 10) / ANIM_W, (hgt - ANIM_TOP - ah) / hgt,
                        12 / ANIM_W, ah / hgt])
    fig.colorbar(sc, cax=cax).set_label("dBm", fontsize=8)
    cax.tick_params(labelsize=7)
    traj, = ax.plot([], [], "-", color="tab:blue", lw=0.8, zorder=4, label="trajectory")
    dots, = ax.plot([], [], "o", color=plt.get_cmap("viridis")(0.6), ms=4, label="packets")
    sources = np.array(s["sources"])
    ax.plot(sources[:, 0], sources[:, 1], "*", color="red", ms=14, label="source")
    goal, = ax.plot([], [], "x", color="limegreen", ms=9, mew=2.5, zorder=6, label="goal")
    est, = ax.plot([], [], "P", color="white", mec="black", ms=10, zorder=5,
                   label="source estimate")
    area = plt.Circle((0, 0), 0, fill=False, ec="magenta", ls="--", lw=1.0, visible=False)
    ax.add_patch(area)
    robot = plt.Circle((tx[0], ty[0]), ROBOT_RADIUS_M, fc=ROBOT_RGB, ec="black", lw=0.6,
                       zorder=10, label="robot")
    ax.add_patch(robot)
    tick, = ax.plot([], [], "-", color="black", lw=1.5, zorder=10)
    ax.legend(handles=[robot, traj, dots, goal, est], loc="upper center", ncol=5, fontsize=8,
              bbox_to_anchor=(0.5, -22 / ah), frameon=False, markerscale=1.5)
    counter = fig.text(ANIM_LEFT / ANIM_W, 1 - 24 / hgt, "", fontsize=11, family="monospace")
    fig.text(1 - 10 / ANIM_W, 1 - 24 / hgt, "%s, seed %s, %s + %s" % (
        os.path.basename(s.get("scenario", "")), s.get("seed"), s.get("strategy"), s.get("model")),
        fontsize=9, ha="right")
    decimals = max(0, int(np.ceil(-np.log10(times[1] - times[0] + 1e-12)))) if len(times) > 1 else 0

    def draw(j, t):
        i = max(1, np.searchsorted(tt, t, side="right"))
        traj.set_data(tx[:i], ty[:i])
        x, y, h = tx[i - 1], ty[i - 1], tth[i - 1]
        robot.center = (x, y)
        c, sn = np.cos(h), np.sin(h)
        tick.set_data([x + ROBOT_RADIUS_M * c, x + 2.2 * ROBOT_RADIUS_M * c],
                      [y + ROBOT_RADIUS_M * sn, y + 2.2 * ROBOT_RADIUS_M * sn])
        n = np.searchsorted(st, t, side="right")
        sc.set_offsets(np.column_stack([sx[:n], sy[:n]]))
        sc.set_array(sv[:n])
        d = np.searchsorted(lt, t, side="right") - 1
        goal.set_data(([gx[d]], [gy[d]]) if d >= 0 else ([], []))
        ok = d >= 0 and np.isfinite(ex[d]) and np.isfinite(ey[d])
        est.set_data(([ex[d]], [ey[d]]) if ok else ([], []))
        area.set_visible(bool(ok and np.isfinite(ea[d])))
        if area.get_visible():
            area.center, area.radius = (ex[d], ey[d]), np.sqrt(ea[d] / np.pi)
        text = "t = %.*f s, travelled %.1f m" % (decimals, t, travelled[i - 1])
        if j == len(times) - 1:
            text += ", %s" % ("reached" if s.get("reached") else "end: %s" % s.get("end"))
        counter.set_text(text)
        fig.canvas.draw()
        return np.asarray(fig.canvas.buffer_rgba())[:, :, :3]

    tmp = "%s.tmp-%d%s" % (out, os.getpid(), ".mp4" if mp4 else ".gif")
    try:
        if mp4:
            enc = subprocess.Popen(
                ["ffmpeg", "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24",
                 "-s", "%dx%d" % (ANIM_W, hgt), "-r", "%g" % fps, "-i", "-", "-c:v", "libx264",
                 "-pix_fmt", "yuv420p", "-f", "mp4", tmp], stdin=subprocess.PIPE,
                stderr=subprocess.PIPE)
            for j, t in enumerate(times):
                enc.stdin.write(np.ascontiguousarray(draw(j, t)).tobytes())
            enc.stdin.close()
            err = enc.stderr.read().decode(errors="replace").strip().splitlines()
            if enc.wait() != 0:
                raise OSError("ffmpeg: %s" % (err[-1] if err else "exit %d" % enc.returncode))
        else:
            from PIL import Image
            frames = (Image.fromarray(draw(j, t)).convert("P", palette=Image.Palette.ADAPTIVE)
                      for j, t in enumerate(times))
            first = next(frames)
            first.save(tmp, format="GIF", save_all=True, append_images=frames,
                       duration=int(round(1000 / fps)), loop=0)
        os.replace(tmp, out)
    except (OSError, ValueError) as e:
        if os.path.exists(tmp):
            os.unlink(tmp)
        die("%s: %s" % (out, e))
    plt.close(fig)
    spread = len(times) == max_frames and len(times) > 1
    print("%s: %d frames of %d x %d, %g fps, %.4g simulated s per video s" % (
        out, len(times), ANIM_W, hgt, fps, times[-1] / (len(times) - 1) * fps if spread else speed))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
