#!/usr/bin/env python3
"""pdr_replay_check.py CAPTURE MAC SAMPLES_TSV T0_US - the percentages rfseek-feed --target
pdr fed to the seeker (samples.tsv, column pdr_pct) against a recomputation here, in
double precision, from tshark's wlan.seq / wlan.frag and frame.time_epoch of the frames
of MAC (with a dBm signal, as the feeder takes them).

The window semantics are the ones docs/MODELS.md states: at each received frame, the
frames received in (t - 1 s, t] over those plus the frames lost in that interval; a frame
lost between two received ones was sent evenly across their gap, so the losses just
before the oldest frame in the window count by the share of that gap inside it.
Retransmissions (same number) and fragments other than 0 give no value. Prints PASS/FAIL
lines; exit 1 on a failure.
"""
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from checks import check, exit_status  # noqa: E402

cap, mac, samples, t0 = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
W = 1_000_000


out = subprocess.run(["tshark", "-r", cap, "-Y", "wlan.sa == %s && radiotap.dbm_antsignal" % mac,
                      "-T", "fields", "-e", "frame.time_epoch", "-e", "wlan.seq", "-e", "wlan.frag",
                      "-E", "occurrence=f"], capture_output=True, text=True, check=True).stdout
frames = []
for line in out.splitlines():
    ts, seq, frag = line.split("\t")
    sec, frac = ts.split(".")
    t_us = int(sec) * 1_000_000 + int(frac[:6]) - t0
    frames.append((t_us, int(seq), int(frag or 0)))

rx = []  # (t, lost before it) of each counted frame
want = []
last = None
for t, seq, frag in frames:
    if frag != 0:
        continue
    if last is not None:
        d = (seq - last) % 4096
        if d == 0:
            continue
        lost = d - 1 if d <= 2048 else 0
    else:
        lost = 0
    last = seq
    rx.append((t, lost))
    inwin = [i for i, (tj, _) in enumerate(rx) if tj > t - W]
    first = inwin[0]
    lost_w = sum(rx[i][1] for i in inwin[1:])
    if first > 0 and rx[first][1] > 0:
        tp, th = rx[first - 1][0], rx[first][0]
        lost_w += rx[first][1] * (th - max(tp, t - W)) / (th - tp)
    else:
        lost_w += rx[first][1]
    r = 100.0 * len(inwin) / (len(inwin) + lost_w)
    want.append((t, r))

got = []
with open(samples) as f:
    head = f.readline().rstrip("\n").split("\t")
    check("samples header names pdr_pct", head[-1] == "pdr_pct", str(head))
    for line in f:
        c = line.rstrip("\n").split("\t")
        got.append((round(float(c[0]) * 1e6), int(c[-1])))

check("one value per new frame", len(got) == len(want) and len(want) >= 5,
      "%d values, %d expected" % (len(got), len(want)))
bad = []
for (tg, vg), (tw, vw) in zip(got, want):
    # Rounding to a whole percentage: a ratio within 1e-4 of .5 may round either way.
    ok = tg == tw and (vg == int(vw + 0.5) or abs(vw - int(vw) - 0.5) < 1e-4 and abs(vg - vw) < 0.51)
    if not ok:
        bad.append("t=%d got %d want %.4f" % (tg, vg, vw))
check("values equal the recomputation from tshark", not bad and len(got) == len(want), "; ".join(bad[:4]))
check("losses are seen (not 100 % throughout)", len({v for _, v in got}) >= 2 and min(v for _, v in got) < 100,
      str(got))
sys.exit(exit_status())
