#!/usr/bin/env python3
"""animate_test.py RFSEEK_SIM - scripts/plot_run.py RUNDIR --animate (its docstring).

A 60 s run of the default office (meta-path + pathloss, the scenario's time cap lowered)
is animated as a GIF; decoded here with Pillow and checked against values computed from
the run's own files and the documented layout, not by the script:
  - the frame count: ceil(T / (speed / fps)) + 1, T the last track.tsv time; with
    --max-frames M exactly M; every frame lasts 1000 / fps ms;
  - the size: 960 x (36 + ceil(map height x scale) + 56, rounded up to even), the scale
    min(840 / map width, 720 / map height) pixels per metre from the map's YAML and PGM;
  - the robot: in the middle frame and the last, the orange pixels are a disc of the robot's
    radius round the track's true position at the frame's time (the last track row not
    after it), mapped to pixels by the layout;
  - the map from a PNG image (the same office converted by Pillow) draws alike;
  - MP4 through ffmpeg when it is installed (ffprobe's frame count), else a one-line error;
  - bad input (missing RUNDIR, bad --fps, unknown option, damaged track.tsv): one stderr
    line, exit 1, no video left behind;
  - the figures' mode: --outdir made when missing; an unknown option, --outdir without a
    value, a map not found: one stderr line, exit 1, no figures.
"""
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

from PIL import Image, ImageSequence

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "lib"))
from checks import check, exit_status  # noqa: E402

SIM = sys.argv[1] if len(sys.argv) > 1 else "build/bin/rfseek-sim"
ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
PLOT = [sys.executable, os.path.join(ROOT, "scripts", "plot_run.py")]
W, LEFT, TOP, BOTTOM, MAXW, MAXH = 960, 40, 36, 56, 840, 720  # plot_run.py's docstring
ROBOT_R = 0.177


def read_tsv(path):
    with open(path) as f:
        head = f.readline().rstrip("\n").split("\t")
        return [dict(zip(head, line.rstrip("\n").split("\t"))) for line in f if line.strip()]


def map_geometry(yaml_path):
    """(x0, y1, scale px/m, height px) of a map by the documented layout."""
    kv = {}
    for line in open(yaml_path):
        if ":" in line and not line.lstrip().startswith("#"):
            k, v = line.split(":", 1)
            kv[k.strip()] = v.split("#")[0].strip()
    res = float(kv["resolution"])
    ox, oy = [float(t) for t in kv["origin"].strip("[]").split(",")[:2]]
    with Image.open(os.path.join(os.path.dirname(yaml_path), kv["image"])) as im:
        w, h = im.size
    mw, mh = w * res, h * res
    s = min(MAXW / mw, MAXH / mh)
    height = TOP + math.ceil(mh * s - 1e-6) + BOTTOM
    return ox, oy + mh, s, height + height % 2


def orange(p):
    return abs(p[0] - 255) < 40 and abs(p[1] - 128) < 40 and p[2] < 60


def disc_fraction(frame, x, y, geo):
    """The fraction of the pixels inside the robot's disc at world (x, y) (1.2 px in from
    its drawn edge) that are orange, and the pixel of its centre."""
    x0, y1, s, _ = geo
    cx, cy = LEFT + (x - x0) * s, TOP + (y1 - y) * s
    px = frame.convert("RGB").load()
    r = ROBOT_R * s - 1.2
    inside = [(i, j) for j in range(int(cy - r) - 1, int(cy + r) + 2)
              for i in range(int(cx - r) - 1, int(cx + r) + 2)
              if math.hypot(i + 0.5 - cx, j + 0.5 - cy) <= r]
    return sum(orange(px[p]) for p in inside) / len(inside), (cx, cy)


def robot_check(name, frame, at, elsewhere, geo):
    """The robot's disc is drawn at world point `at` and not at `elsewhere`."""
    f, c = disc_fraction(frame, *at, geo)
    g, c2 = disc_fraction(frame, *elsewhere, geo)
    check(name, f >= 0.9 and g <= 0.2, "%.0f %% orange round (%.1f, %.1f), %.0f %% round (%.1f, %.1f)"
          % (100 * f, c[0], c[1], 100 * g, c2[0], c2[1]))


def run_plot(*args, env=None):
    return subprocess.run(PLOT + list(args), capture_output=True, text=True, env=env, cwd=ROOT)


def one_line_error(name, p, pattern, leftover):
    lines = p.stderr.splitlines()
    check(name, p.returncode == 1 and len(lines) == 1 and pattern in lines[0]
          and lines[0].startswith("plot_run.py: ") and not os.path.exists(leftover),
          "exit %d, stderr %r, %s %s" % (p.returncode, p.stderr[:300], leftover,
                                         "exists" if os.path.exists(leftover) else "absent"))


def frames(path):
    with Image.open(path) as im:
        return [(f.copy(), f.info.get("duration")) for f in ImageSequence.Iterator(im)]


def main():
    tmp = tempfile.mkdtemp(prefix="rfs_animate.")
    try:
        return run(tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def run(tmp):
    scn_src = os.path.join(ROOT, "scenarios", "default.yaml")
    maps = os.path.join(ROOT, "scenarios", "maps")
    text = open(scn_src).read()
    text = text.replace("map: maps/office.yaml", "map: %s/office.yaml" % maps)
    # radius 0: the run never counts as reached, so it ends on the 60 s limit
    text = text.replace("stop: {radius_m: 1.5, max_distance_m: 150, max_time_s: 900}",
                        "stop: {radius_m: 0, max_distance_m: 150, max_time_s: 60}")
    scn = os.path.join(tmp, "short.yaml")
    open(scn, "w").write(text)
    run_dir = os.path.join(tmp, "run")
    p = subprocess.run([SIM, scn, "--seed", "1", "--model", "pathloss", "--strategy", "meta-path",
                        "--quiet", "--out", run_dir], capture_output=True, text=True, cwd=ROOT)
    check("short_run", p.returncode == 0, p.stderr[:300])
    if p.returncode:
        return exit_status()
    track = read_tsv(os.path.join(run_dir, "track.tsv"))
    summary = json.load(open(os.path.join(run_dir, "summary.json")))
    t_end = float(track[-1]["t_s"])
    check("short_run_60_s", summary["end"] == "time" and 59.5 <= t_end <= 60.0,
          "end %s, last track row at %.3f s" % (summary["end"], t_end))
    geo = map_geometry(os.path.join(maps, "office.yaml"))

    fps, speed = 4, 6
    gif = os.path.join(tmp, "run.gif")
    p = run_plot(run_dir, "--animate", "--fps", str(fps), "--speed", str(speed), "--out", gif)
    check("animate_gif", p.returncode == 0 and os.path.exists(gif), p.stderr[:300])
    if p.returncode:
        return exit_status()
    fr = frames(gif)
    dt = speed / fps
    want = math.ceil(t_end / dt) + 1
    check("gif_frame_count", len(fr) == want, "%d frames, want %d" % (len(fr), want))
    check("gif_frame_duration", all(d == 1000 // fps for _, d in fr),
          str(sorted(set(d for _, d in fr))))
    check("gif_size", fr[0][0].size == (W, geo[3]), "%s, want %dx%d" % (fr[0][0].size, W, geo[3]))
    times = [k * dt for k in range(want - 1)] + [t_end]

    def pos(t):
        row = ([r for r in track if float(r["t_s"]) <= t + 1e-9] or track)[-1]
        return float(row["x_m"]), float(row["y_m"])

    # The last frame, and the frame whose robot is farthest from the last one: each shows
    # the disc where the track says and not where the other one is.
    last = pos(t_end)
    k = max(range(want - 1), key=lambda k: math.dist(pos(times[k]), last))
    check("robot_moved (%.1f m between frames %d and %d)" % (math.dist(pos(times[k]), last), k,
                                                            want - 1),
          math.dist(pos(times[k]), last) > 1.0)
    robot_check("gif_robot_frame_%d_at_%.1f_s" % (k, times[k]), fr[k][0], pos(times[k]), last, geo)
    robot_check("gif_robot_last_frame_at_%.1f_s" % t_end, fr[-1][0], last, pos(times[k]), geo)

    capped = os.path.join(tmp, "capped.gif")
    p = run_plot(run_dir, "--animate", "--max-frames", "7", "--out", capped)
    fr7 = frames(capped) if p.returncode == 0 else []
    check("gif_max_frames", len(fr7) == 7, "exit %d, %d frames" % (p.returncode, len(fr7)))
    if fr7:
        robot_check("gif_max_frames_robot", fr7[3][0], pos(t_end / 2), last, geo)

    # The same run on the office map as a PNG image: the same picture.
    png_yaml = os.path.join(tmp, "office_png.yaml")
    Image.open(os.path.join(maps, "office.pgm")).save(os.path.join(tmp, "office.png"))
    open(png_yaml, "w").write(open(os.path.join(maps, "office.yaml")).read()
                              .replace("image: office.pgm", "image: office.png"))
    png_run = os.path.join(tmp, "png_run")
    shutil.copytree(run_dir, png_run)
    s2 = dict(summary, map=png_yaml)
    json.dump(s2, open(os.path.join(png_run, "summary.json"), "w"))
    p = run_plot(png_run, "--animate", "--max-frames", "7", "--out", os.path.join(tmp, "png.gif"))
    frp = frames(os.path.join(tmp, "png.gif")) if p.returncode == 0 else []
    check("png_map_same_frames", len(frp) == 7 and all(
        a.convert("RGB").tobytes() == b.convert("RGB").tobytes() for (a, _), (b, _) in zip(frp, fr7)),
        "exit %d: %s" % (p.returncode, p.stderr[:200]))

    # MP4: encoded by ffmpeg when installed; without it on PATH, one line.
    mp4 = os.path.join(tmp, "run.mp4")
    if shutil.which("ffmpeg") and shutil.which("ffprobe"):
        p = run_plot(run_dir, "--animate", "--fps", str(fps), "--speed", str(speed), "--out", mp4)
        q = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0",
                            "-show_entries", "stream=nb_read_frames,width,height,codec_name",
                            "-of", "csv=p=0", mp4], capture_output=True, text=True)
        check("mp4_frames_and_size", p.returncode == 0 and
              q.stdout.strip() == "h264,%d,%d,%d" % (W, geo[3], want),
              "exit %d %s, ffprobe %r" % (p.returncode, p.stderr[:200], q.stdout))
    else:
        print("SKIP mp4_frames_and_size: ffmpeg is not installed")
    env = dict(os.environ, PATH=os.path.join(tmp, "no-such-dir"))
    one_line_error("mp4_without_ffmpeg", run_plot(run_dir, "--animate", "--out", mp4 + "2.mp4",
                                                  env=env), "needs ffmpeg", mp4 + "2.mp4")

    # The figures' mode: --outdir made when missing; bad options and a map not found.
    figs = os.path.join(tmp, "figs", "new")
    p = run_plot(run_dir, "--outdir", figs)
    made = os.path.join(figs, "trajectory.png")
    check("outdir_made", p.returncode == 0 and os.path.exists(made), p.stderr[:300])
    if os.path.exists(made):
        with Image.open(made) as im:
            check("outdir_trajectory_png", im.format == "PNG" and im.size[0] > 500, str(im.size))
    left = os.path.join(run_dir, "trajectory.png")
    one_line_error("figures_unknown_option", run_plot(run_dir, "--bogus"), "--bogus", left)
    one_line_error("figures_outdir_without_value", run_plot(run_dir, "--outdir"), "--outdir", left)
    moved = os.path.join(tmp, "moved")
    shutil.copytree(run_dir, moved)
    with open(os.path.join(moved, "summary.json")) as f:
        sm = json.load(f)
    sm["map"] = "maps/nowhere.yaml"
    with open(os.path.join(moved, "summary.json"), "w") as f:
        json.dump(sm, f)
    one_line_error("figures_map_not_found",
                   run_plot(moved, "--outdir", os.path.join(tmp, "moved_figs")),
                   "relative to where rfseek-sim ran", os.path.join(tmp, "moved_figs"))

    out = os.path.join(tmp, "bad.gif")
    one_line_error("missing_rundir", run_plot(os.path.join(tmp, "nope"), "--animate", "--out", out),
                   "nope", out)
    for v in ("x", "0", "61", "nan"):
        one_line_error("bad_fps_%s" % v, run_plot(run_dir, "--animate", "--fps", v, "--out", out),
                       "--fps: expected a number in [1, 60], got %s" % v, out)
    one_line_error("bad_speed", run_plot(run_dir, "--animate", "--speed", "-1", "--out", out),
                   "--speed", out)
    one_line_error("missing_value", run_plot(run_dir, "--animate", "--fps"), "--fps", out)
    one_line_error("unknown_option", run_plot(run_dir, "--animate", "--bogus", "1", "--out", out),
                   "--bogus", out)
    with open(os.path.join(png_run, "track.tsv"), "a") as f:
        f.write("1.0\tabc\t2\t0\t0\t0\t0\t0\n")
    one_line_error("damaged_track", run_plot(png_run, "--animate", "--out", out), "png_run", out)
    one_line_error("unwritable_out", run_plot(run_dir, "--animate", "--max-frames", "2", "--out",
                                              os.path.join(tmp, "no", "x.gif")),
                   "no/x.gif", os.path.join(tmp, "no"))
    left = [f for f in os.listdir(tmp) if ".tmp-" in f]
    check("no_temporary_files_left", not left, str(left))
    return exit_status()


if __name__ == "__main__":
    sys.exit(main())
