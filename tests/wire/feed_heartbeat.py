#!/usr/bin/env python3
"""feed_heartbeat.py FEED - the receiver heartbeat in rfseek-feed --pose.

Builds a capture in pure Python (classic pcap, radiotap with a dBm signal, 802.11 data
frames) and a pose CSV for scenarios/default.yaml: the robot creeps east along the
corridor for 60 s; the source (02:00:00:00:00:01) is heard every 20 ms for the first 10 s
only. Three captures differ in what comes after 10 s:
  other   another transmitter every 20 ms until 60 s (the channel is alive, the source
          unheard: a dead zone);
  quiet   nothing at all (the capture shows no life: a dead receiver);
and the "other" capture replayed with the scenario's radio.receiver.heartbeat false.
The seeker decides only while its measurement stream is fresh; the goal of a replayed
run ends by the recorded poses (timeouts), so decisions after 10.2 s appear only when the
heartbeat keeps the stream fresh. Checks (counted from log.tsv, times from this script):
  other + heartbeat: decisions after 10.2 s;  quiet + heartbeat: none;
  other without heartbeat: none; the three runs agree on every decision up to 10 s.
"""
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "feed"))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import pcap_build  # noqa: E402
from checks import check, exit_status  # noqa: E402

FEED = sys.argv[1]
SCEN = "scenarios/default.yaml"
SRC = bytes.fromhex("020000000001")
OTHER = bytes.fromhex("020000000099")
T0 = 1700000000000000


def capture(path, other):
    recs = []
    for k in range(3000):
        t = T0 + k * 20000 + 7
        if t < T0 + 10_000_000:
            recs.append(pcap_build.record(t, SRC, k, -60 - k % 5))
        elif other:
            recs.append(pcap_build.record(t, OTHER, k, -30))
    pcap_build.write(path, recs)


def decisions(out):
    with open(os.path.join(out, "log.tsv")) as f:
        rows = [line.rstrip("\n").split("\t") for line in f][1:]
    return [(float(r[1]), r[0], r[7]) for r in rows]


def main():
    tmp = tempfile.mkdtemp(prefix="rfs_feed_hb_")
    try:
        return run(tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def run(tmp):
    with open(os.path.join(tmp, "poses.csv"), "w") as f:
        f.write("t_us,x_m,y_m,theta_rad\n")
        for k in range(601):
            f.write("%d,%.6f,6.000000,0.000000\n" % (T0 + k * 100000, 8.0 + 0.01 * k))
    with open(SCEN) as f:
        text = f.read()
    off = text.replace("loss_width_db: 1.5}", "loss_width_db: 1.5, heartbeat: false}")
    off = off.replace("map: maps/", "map: " + os.path.abspath("scenarios/maps") + "/")
    if off == text:
        check("scenario without heartbeat", False, SCEN + " changed")
        return 1
    with open(os.path.join(tmp, "off.yaml"), "w") as f:
        f.write(off)
    capture(os.path.join(tmp, "other.pcap"), True)
    capture(os.path.join(tmp, "quiet.pcap"), False)
    runs = {}
    for name, cap, scen in (("other", "other.pcap", SCEN), ("quiet", "quiet.pcap", SCEN),
                            ("other-off", "other.pcap", os.path.join(tmp, "off.yaml"))):
        out = os.path.join(tmp, name)
        p = subprocess.run([FEED, os.path.join(tmp, cap), "--pose", os.path.join(tmp, "poses.csv"),
                            "--scenario", scen, "--out", out, "--seed", "3"], capture_output=True, text=True)
        check("feed %s exits 0" % name, p.returncode == 0, p.stderr.strip())
        if p.returncode != 0:
            return 1
        runs[name] = decisions(out)
    late = {k: [d for d in v if d[0] > 10.2] for k, v in runs.items()}
    early = {k: [d for d in v if d[0] <= 10.0] for k, v in runs.items()}
    check("heartbeat from another transmitter: the seeker decides on in the dead zone "
          "(%d decisions after 10.2 s)" % len(late["other"]), len(late["other"]) >= 1, str(runs["other"]))
    check("no frame at all: no heartbeat, no decision after 10.2 s", len(late["quiet"]) == 0, str(late["quiet"]))
    check("heartbeat off in the scenario: no decision after 10.2 s", len(late["other-off"]) == 0,
          str(late["other-off"]))
    check("the three runs agree up to 10 s (%d decisions)" % len(early["other"]),
          len(early["other"]) >= 1 and early["other"] == early["quiet"] == early["other-off"], str(early))
    return exit_status()


if __name__ == "__main__":
    sys.exit(main())
