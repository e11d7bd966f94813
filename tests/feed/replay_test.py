#!/usr/bin/env python3
"""rfseek-feed --pose: replay a recorded run through the seeker.

Builds a capture (pure python pcap bytes) and a pose CSV for scenarios/default.yaml: the
robot drives east along the corridor from the start at 0.5 m/s for 30 s, poses at 10 Hz;
the source sends 50 frames/s with a log-distance signal, every 10th frame lost (a gap in
the sequence numbers), plus frames before the first pose, after the last one and from
another transmitter. Checks, against values computed here in double precision:
samples.tsv positions (linear interpolation of the poses at each frame's time), dBm and
times; track.tsv; summary.json (packets received and sent from the sequence gaps,
distance travelled, end, final position); log.tsv's header is the simulator's and the
first decision is the initial move. Then bad pose files and options.
usage: replay_test.py FEED
"""
import json
import math
import os
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import pcap_build  # noqa: E402
from checks import check, exit_status  # noqa: E402

FEED = sys.argv[1]
SCEN = "scenarios/default.yaml"
SRC_MAC = bytes.fromhex("020000000001")
OTHER = bytes.fromhex("020000000099")
SOURCE_XY = (27.5, 10.0)
T0 = 1700000000000000  # first pose, microseconds since the epoch


def pose_at(poses, t):
    for (ta, xa, ya, _), (tb, xb, yb, _) in zip(poses, poses[1:]):
        if ta <= t <= tb:
            a = (t - ta) / (tb - ta)
            return xa + a * (xb - xa), ya + a * (yb - ya)
    raise ValueError(t)


def main():
    tmp = tempfile.mkdtemp(prefix="rfs_replay_")
    poses = [(T0 + k * 100000, 8.0 + 0.05 * k, 6.0, 0.0) for k in range(301)]  # 30 s
    with open(os.path.join(tmp, "poses.csv"), "w") as f:
        f.write("t_us,x_m,y_m,theta_rad\n")
        for t, x, y, th in poses:
            f.write("%d,%.6f,%.6f,%.6f\n" % (t, x, y, th))
    recs = []
    want = []  # (t_rel_s, x, y, dbm) for frames inside the poses' span
    seq = 100
    sent_in = received_in = 0
    for k in range(-20, 1510):
        t = T0 + k * 20000 + 7
        seq = (seq + 1) & 0xFFF
        inside = T0 <= t <= poses[-1][0]
        if k % 10 == 3:
            sent_in += inside
            continue  # lost
        if inside:
            x, y = pose_at(poses, t)
            d = max(1.0, math.hypot(x - SOURCE_XY[0], y - SOURCE_XY[1]))
            dbm = int(round(-40 - 30 * math.log10(d)))
            want.append(((t - T0) / 1e6, x, y, dbm))
            sent_in += 1
            received_in += 1
        else:
            dbm = -70
        recs.append(pcap_build.record(t, SRC_MAC, seq, dbm))
        if k % 7 == 0:
            recs.append(pcap_build.record(t + 1, OTHER, k, -30))
    cap = os.path.join(tmp, "run.pcap")
    pcap_build.write(cap, recs)

    out = os.path.join(tmp, "out")
    p = subprocess.run([FEED, cap, "--pose", os.path.join(tmp, "poses.csv"), "--scenario", SCEN,
                        "--out", out, "--seed", "3", "--stats"], capture_output=True, text=True)
    check("replay exits 0", p.returncode == 0, p.stderr.strip())
    if p.returncode != 0:
        return
    check("replay output complete, no temporary left",
          sorted(os.listdir(out)) == ["log.tsv", "samples.tsv", "summary.json", "track.tsv"]
          and not any(n.startswith("out.tmp") for n in os.listdir(tmp)), str(os.listdir(tmp)))
    with open(os.path.join(out, "samples.tsv")) as f:
        rows = [l.rstrip("\n").split("\t") for l in f]
    check("samples header", rows[0] == ["t_s", "src", "x_m", "y_m", "travelled_m", "dbm"], str(rows[0]))
    rows = rows[1:]
    check("samples: one per received frame in the poses' span", len(rows) == len(want),
          "%d rows, want %d" % (len(rows), len(want)))
    bad = [(r, w) for r, w in zip(rows, want)
           if abs(float(r[0]) - w[0]) > 1e-6 or r[1] != "0" or abs(float(r[2]) - w[1]) > 0.0006
           or abs(float(r[3]) - w[2]) > 0.0006 or int(r[5]) != w[3]
           or abs(float(r[4]) - (w[1] - 8.0)) > 0.0006]
    check("samples: time, interpolated position, travelled and dBm equal the reference", not bad,
          str(bad[:2]))
    with open(os.path.join(out, "track.tsv")) as f:
        trk = f.read().splitlines()
    check("track: one row per pose", len(trk) == 1 + len(poses), str(len(trk)))
    with open(os.path.join(out, "summary.json")) as f:
        sm = json.load(f)
    check("summary: packets_received", sm["packets_received"] == received_in,
          "%s want %d" % (sm["packets_received"], received_in))
    check("summary: packets_sent from the sequence gaps", sm["packets_sent"] == sent_in,
          "%s want %d" % (sm["packets_sent"], sent_in))
    check("summary: distance travelled 15 m", abs(sm["distance_travelled_m"] - 15.0) < 0.002,
          str(sm["distance_travelled_m"]))
    check("summary: ends at the last pose, not reached", sm["end"] == "time" and sm["reached"] is False
          and abs(sm["final_x_m"] - 23.0) < 0.002 and abs(sm["sim_time_s"] - 30.0) < 1e-3, str(sm))
    check("summary: final distance to the goal",
          abs(sm["final_distance_m"] - math.hypot(23.0 - 27.5, 6.0 - 10.0)) < 0.002, str(sm["final_distance_m"]))
    check("summary: the seeker decided", sm["iterations"] >= 1 and sm["seed"] == 3, str(sm))
    with open(os.path.join(out, "log.tsv")) as f:
        log = [l.rstrip("\n").split("\t") for l in f]
    sim_header = ("iteration\tt_s\tx_m\ty_m\ttheta_rad\test_x_m\test_y_m\tkind\treason\trelearned\t"
                  "prediction_db\tmean_db\tepsilon\tgoal_x_m\tgoal_y_m\tmax_x_m\tmax_y_m\tpath_m\t"
                  "samples\ttravelled_m\test_src_x_m\test_src_y_m\test_n\test_w_db\test_p0\t"
                  "est_area_m2").split("\t")
    check("log: the simulator's header", log[0] == sim_header, str(log[0]))
    check("log: one row per decision, first the initial move",
          len(log) - 1 == sm["iterations"] and log[1][0] == "0" and log[1][7] == "initial", str(log[:2]))
    # The summary's decision counts are the log's rows counted (as rfseek-sim's): kinds, how
    # the goals before them ended, and a wait for each (the deciding period at least).
    rows = log[1:]
    counts = {"greedy": sum(r[7] == "greedy" for r in rows), "epsilon": sum(r[7] == "epsilon" for r in rows),
              "goal_timeouts": sum(r[8].startswith("prev=timeout") for r in rows),
              "goal_blocked": sum(r[8].startswith("prev=blocked") for r in rows)}
    check("summary: decision counts from the log " + str(counts),
          all(sm[k] == v for k, v in counts.items()) and counts["goal_timeouts"] + counts["greedy"] > 0,
          str({k: sm[k] for k in counts}))
    check("summary: decision waits counted", sm["decision_wait_max_s"] >= 0.05 and
          sm["slow_decisions"] is not None and sm["plan_wait_max"] is not None, str(sm))
    check("stats: frames outside the poses counted",
          "not fed, before the first pose" in p.stderr and "not fed, after the last pose" in p.stderr, p.stderr)

    # bad input: one line naming file:line, exit 1, nothing written
    def bad(name, text, rc, pattern, extra=()):
        path = os.path.join(tmp, name + ".csv")
        with open(path, "w") as f:
            f.write(text)
        o = os.path.join(tmp, "bad-" + name)
        q = subprocess.run([FEED, cap, "--pose", path, "--scenario", SCEN, "--out", o] + list(extra),
                           capture_output=True, text=True)
        err = q.stderr.strip()
        check("bad %s: exit %d, '%s', nothing written" % (name, rc, pattern),
              q.returncode == rc and pattern in err and len(err.splitlines()) == 1
              and not any(n.startswith("bad-" + name) for n in os.listdir(tmp)), "%d %s" % (q.returncode, err))

    good = "t_us,x_m,y_m,theta_rad\n%d,8,6,0\n%d,9,6,0\n" % (T0, T0 + 1000000)
    bad("header", "t,x,y,theta\n1,2,3,4\n", 1, "header.csv:1: header must be 't_us,x_m,y_m,theta_rad'")
    bad("order", "t_us,x_m,y_m,theta_rad\n%d,8,6,0\n%d,9,6,0\n" % (T0, T0), 1,
        "order.csv:3: t_us: %d is not after the previous pose" % T0)
    bad("number", "t_us,x_m,y_m,theta_rad\n%d,8,abc,0\n" % T0, 1, "number.csv:2: y_m: not a finite number")
    bad("nan", "t_us,x_m,y_m,theta_rad\n%d,8,6,nan\n" % T0, 1, "nan.csv:2: theta_rad: not a finite number")
    bad("short", "t_us,x_m,y_m,theta_rad\n%d,8,6,0\n" % T0, 1, "short.csv: fewer than 2 poses")
    # times and positions outside what the replay can compute with (int64 differences,
    # Q16.16 metres): refused by range, not overflowed
    bad("t_min", "t_us,x_m,y_m,theta_rad\n-9223372036854775808,8,6,0\n%d,9,6,0\n" % T0, 1,
        "t_min.csv:2: t_us: -9223372036854775808 out of range (0 .. 9007199254740992 microseconds since the epoch)")
    bad("t_max", "t_us,x_m,y_m,theta_rad\n%d,8,6,0\n9223372036854775807,9,6,0\n" % T0, 1,
        "t_max.csv:3: t_us: 9223372036854775807 out of range (0 .. 9007199254740992")
    bad("x_range", "t_us,x_m,y_m,theta_rad\n%d,1e300,6,0\n" % T0, 1,
        "x_range.csv:2: x_m: 1e+300 out of range (-32767 .. 32767 m)")
    bad("macs", good, 2, "--mac: 2 addresses given", ["--mac", "02:00:00:00:00:01", "--mac", "02:00:00:00:00:02"])
    bad("seed", good, 2, "--seed: '-1' is not a non-negative integer", ["--seed", "-1"])
    q = subprocess.run([FEED, cap, "--pose", "x.csv"], capture_output=True, text=True)
    check("--pose without --scenario/--out", q.returncode == 2 and "--pose needs --scenario and --out" in q.stderr,
          q.stderr)
    q = subprocess.run([FEED, cap, "--mac", "02:00:00:00:00:01", "--out", "x"], capture_output=True, text=True)
    check("--out without --pose", q.returncode == 2 and "only go with --pose" in q.stderr, q.stderr)
    # A heading of 1e9 rad is wrapped at once (it looped ~1.6e8 times): the track holds
    # the IEEE remainder by 2 pi, computed here by Python's math.
    spin = os.path.join(tmp, "spin.csv")
    with open(spin, "w") as f:
        f.write("t_us,x_m,y_m,theta_rad\n%d,8,6,1e9\n%d,9,6,-1e9\n" % (T0, T0 + 1000000))
    try:
        q = subprocess.run([FEED, cap, "--pose", spin, "--scenario", SCEN, "--out", os.path.join(tmp, "spin")],
                           capture_output=True, text=True, timeout=20)
        trk = [l.split("\t") for l in open(os.path.join(tmp, "spin", "track.tsv")).read().splitlines()]
        want = ["%.4f" % math.remainder(1e9, 2 * math.pi), "%.4f" % math.remainder(-1e9, 2 * math.pi)]
        check("theta 1e9: wrapped in the track, exit 0", q.returncode == 0 and [r[3] for r in trk[1:]] == want,
              "%d %s %s" % (q.returncode, q.stderr.strip(), trk[1:]))
    except (subprocess.TimeoutExpired, OSError) as e:
        check("theta 1e9: wrapped in the track, exit 0", False, str(e))

    # SIGTERM or SIGINT during the replay: the process dies of it and leaves no DIR.tmp-PID.
    # The run (an hour of poses) is stopped the moment its temporary directory appears.
    long_poses = os.path.join(tmp, "long.csv")
    with open(long_poses, "w") as f:
        f.write("t_us,x_m,y_m,theta_rad\n")
        f.writelines("%d,%.2f,6,0\n" % (T0 + k * 100000, 8 + (k % 100) * 0.01) for k in range(36001))
    long_cap = os.path.join(tmp, "long.pcap")
    pcap_build.write(long_cap, [pcap_build.record(T0 + k * 20000, SRC_MAC, k, -70) for k in range(180000)])
    for sig in (signal.SIGTERM, signal.SIGINT):
        out = os.path.join(tmp, "killed")
        q = subprocess.Popen([FEED, long_cap, "--pose", long_poses, "--scenario", SCEN, "--out", out],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        tmpdir = "%s.tmp-%d" % (out, q.pid)
        deadline = time.monotonic() + 30
        while not os.path.isdir(tmpdir) and q.poll() is None and time.monotonic() < deadline:
            time.sleep(0.0005)
        seen = os.path.isdir(tmpdir)
        q.send_signal(signal.SIGSTOP)  # hold it mid-run, then stop it for good
        q.send_signal(sig)
        q.send_signal(signal.SIGCONT)
        rc = q.wait()
        left = [n for n in os.listdir(tmp) if n.startswith("killed")]
        check("%s mid-replay: killed by it, nothing left" % sig.name, seen and rc == -sig and not left,
              "seen %s, exit %d, left %s" % (seen, rc, left))
    if os.environ.get("KEEP") is None:
        subprocess.run(["rm", "-rf", tmp])
    else:
        print("kept " + tmp)


main()
sys.exit(exit_status())
