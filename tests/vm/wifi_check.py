#!/usr/bin/env python3
"""wifi_check.py OUT AP GEN - the live 802.11 VM run (tests/vm/wifi_inner.sh), checked on
the host from the files it left in OUT: mon0.pcap (tcpdump on the monitor interface),
rfseekd.lcmlog (rfseekd --log: every message it received and sent), can.log (candump -L
vcan0), feed.err and rfseekd.err (the programs' last lines). AP is the access point's MAC;
GEN the lcm-gen Python types (BUILD/gen/python) scripts/lcm_log.py decodes with.

References independent of our code: tshark reads the capture; canmatrix decodes the CAN
frames from can/rfseek.dbc (scripts/check_candump.py, which also checks every frame's
checksum, counter and cycle time); lcm-gen's Python classes decode the LCM log. The
phases are found in the data, not in the script's timing: the channel went silent after
the last RSSI message; the feed hung (SIGSTOP) in the one heartbeat gap over a second.
Checks:
  - every RSSI message rfseekd received equals a frame tshark shows from AP (time to the
    microsecond, dBm), and from the first one on tshark shows no frame it did not get;
    the signal took at least 5 values (hwsim's rx_rssi stepped);
  - no heartbeat lost (published = logged = counted by rfseekd, counts consecutive); apart
    from the hang, no gap of 150 ms (the controller's RSSI timeout) or more; they went on
    for 2 s of silent channel;
  - wheels: while the channel is silent the controller never reports its RSSI stale and
    drives; after the feed hangs, the first control step past the 150 ms timeout (so within
    200 ms) reports the RSSI stale with a Stop, and from 200 ms every WHEEL_CMD is Stop with
    zero speeds and every STATUS has the fault until the heartbeats come back; then it
    drives again.
A failed check while the 20 Hz poses show the VM stalled (a loaded host under TCG) exits 3,
inconclusive: run_wifi_vm_test.sh then runs the VM once more.
"""
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
sys.path.insert(0, os.path.join(ROOT, "tests", "lib"))
import lcm_log  # noqa: E402
from checks import check, exit_status  # noqa: E402

TIMEOUT_US = 150000  # the controller's RSSI timeout (common/rfs_seek.c)
STOP_US = 200000     # that plus one 50 ms control period
STALL_US = 100000    # two pose periods: the VM was not scheduled (a loaded host under TCG)
INCONCLUSIVE = 3     # the exit status when a timing check failed while the VM stalled
FAULT_RSSI_STALE = 1 << 1  # STATUS Faults bit 1 (docs/CAN.md)


def epoch_us(s):
    """tshark's frame.time_epoch ("sec.nnnnnnnnn") in whole microseconds."""
    sec, frac = s.split(".")
    return int(sec) * 1000000 + int((frac + "000000")[:6])


def tshark_frames(pcap, ap):
    out = subprocess.run(["tshark", "-r", pcap, "-Y", "wlan.sa == %s && radiotap.dbm_antsignal" % ap,
                          "-T", "fields", "-e", "frame.time_epoch", "-e", "radiotap.dbm_antsignal",
                          "-E", "occurrence=f"], capture_output=True, text=True, check=True).stdout
    return [(epoch_us(t), int(d)) for t, d in (line.split("\t") for line in out.splitlines())]


def lcm_messages(log, gen):
    types = lcm_log.load_types(gen)
    rssi, hb, pose = [], [], []
    for _, _, channel, data in lcm_log.events(log):
        if channel == "RFS_POSE":
            pose.append(lcm_log.decode(data, types)[1].utime)
        elif channel == "RFS_RSSI":
            m = lcm_log.decode(data, types)[1]
            rssi.append((m.utime, m.source, m.dbm))
        elif channel == "RFS_RSSI_STATUS":
            m = lcm_log.decode(data, types)[1]
            hb.append((m.utime, m.seq))
    return rssi, hb, pose


def stalls(pose):
    """The VM's stalls: gaps of STALL_US or more between the 20 Hz poses (lcm_tool pose, a
    process the test never stops) as (start, length) in microseconds."""
    return [(a, b - a) for a, b in zip(pose, pose[1:]) if b - a >= STALL_US]


def can_frames(log):
    """(t_us, name, {signal: raw}) of every frame, decoded by canmatrix; prints the PASS/FAIL
    lines of check_candump.py's own checks."""
    py = "/usr/bin/python3"
    dbc = os.path.join(ROOT, "can", "rfseek.dbc")
    tool = os.path.join(ROOT, "scripts", "check_candump.py")
    full = subprocess.run([py, tool, dbc, log], capture_output=True, text=True)
    for line in full.stdout.splitlines():
        if line.startswith("FAIL "):
            check("wifi-candump " + line[5:], False, "check_candump.py")
    check("wifi-candump-valid (check_candump.py: checksums, DLCs, ranges, counters, 50 ms cycles)",
          full.returncode == 0, full.stdout[-300:] + full.stderr[-300:])
    out = subprocess.run([py, tool, dbc, log, "--decode"], capture_output=True, text=True, check=True).stdout
    frames = []
    for line in out.splitlines():
        f = line.split("\t")
        if not f[0].isdigit():  # its PASS lines, printed above
            continue
        frames.append((int(f[0]), f[1], dict(kv.split("=") for kv in f[2:])))
    return frames


def count(path, pattern):
    with open(path) as f:
        m = re.search(pattern, f.read())
    return int(m.group(1)) if m else -1


def main(argv):
    out, ap, gen = argv[1], argv[2], argv[3]
    frames = tshark_frames(os.path.join(out, "mon0.pcap"), ap)
    rssi, hb, pose = lcm_messages(os.path.join(out, "rfseekd.lcmlog"), gen)
    if not rssi or len(hb) < 3:
        check("wifi-lcm-messages", False, "%d RSSI, %d heartbeats in rfseekd's log" % (len(rssi), len(hb)))
        return exit_status()

    # The dBm values against tshark.
    got = [(t, d) for t, _, d in rssi]
    want = [(t, d) for t, d in frames if t >= rssi[0][0]]
    values = sorted({d for _, d in got})
    published = count(os.path.join(out, "feed.err"), r"packets, (\d+) lines")
    check("wifi-rssi-equals-tshark (%d RSSI messages = tshark's frames from %s from the first on, "
          "time and dBm; %d published)" % (len(got), ap, published),
          got == want and published == len(got) and len(got) >= 40,
          "first differences: %s" % [(a, b) for a, b in zip(got, want) if a != b][:3] +
          " lengths %d %d, published %d" % (len(got), len(want), published))
    check("wifi-rssi-source-0 (the first --mac)", all(s == 0 for _, s, _ in rssi))
    check("wifi-dbm-varies (%d values, %d..%d dBm)" % (len(values), values[0], values[-1]), len(values) >= 5,
          str(values))

    # Heartbeats.
    n_pub = count(os.path.join(out, "feed.err"), r"(\d+) receiver heartbeats published")
    n_ctl = count(os.path.join(out, "rfseekd.err"), r"(\d+) receiver heartbeats")
    check("wifi-heartbeats-none-lost (%d published, %d in the log, %d counted by rfseekd)" % (n_pub, len(hb), n_ctl),
          n_pub == len(hb) == n_ctl and [s for _, s in hb] == list(range(len(hb))), str(hb[:5]))
    gaps = [(hb[i + 1][0] - hb[i][0], i) for i in range(len(hb) - 1)]
    long = [(g, i) for g, i in gaps if g >= 1000000]
    short = sorted(g for g, _ in gaps if g < 1000000)
    if len(long) != 1:
        check("wifi-feed-hang-found (one heartbeat gap over 1 s)", False, str(long))
        return exit_status()
    hang_gap, k = long[0]
    hang0, hang1 = hb[k][0], hb[k + 1][0]
    last_rssi = rssi[-1][0]
    check("wifi-heartbeat-spacing (apart from the %.2f s hang: median %.1f ms, max %.1f ms < 150 ms)"
          % (hang_gap / 1e6, short[len(short) // 2] / 1e3, short[-1] / 1e3), short[-1] < TIMEOUT_US)
    silent = [t for t, _ in hb if last_rssi < t <= hang0]
    check("wifi-heartbeats-through-silence (%d over %.2f s after the last frame)"
          % (len(silent), (hang0 - last_rssi) / 1e6), hang0 - last_rssi >= 2000000 and len(silent) >= 20)

    # The wheels.
    can = can_frames(os.path.join(out, "can.log"))
    wheel = [(t, s) for t, n, s in can if n == "WHEEL_CMD"]
    status = [(t, s) for t, n, s in can if n == "STATUS"]

    def moving(s):
        return s["Stop"] == "0" and (s["LeftSpeed"] != "0" or s["RightSpeed"] != "0")

    def stale(s):
        return int(s["Faults"]) & FAULT_RSSI_STALE != 0

    w_beacons = [s for t, s in wheel if rssi[0][0] + 500000 <= t <= last_rssi]
    w_silent = [s for t, s in wheel if last_rssi + STOP_US <= t <= hang0]
    s_silent = [s for t, s in status if last_rssi + STOP_US <= t <= hang0]
    w_hung = [s for t, s in wheel if hang0 + STOP_US <= t <= hang1]
    s_hung = [s for t, s in status if hang0 + STOP_US <= t <= hang1]
    w_back = [s for t, s in wheel if t >= hang1 + STOP_US and t <= hb[-1][0]]
    # The first control step after the timeout (its STATUS, as candump stamps it, a little
    # after the step's clock) reports the RSSI stale, none before it; its WHEEL_CMD, sent
    # just before, is the first Stop.
    first_stale = next((t for t, s in status if t > hang0 and stale(s)), None)
    after = next((t for t, s in status if t > hang0 + TIMEOUT_US + 5000), None)
    first_stop = next((t for t, s in wheel if t > hang0 and not moving(s)), None)
    n_mov = sum(map(moving, w_silent))
    check("wifi-wheels-drive-on-beacons (%d of %d WHEEL_CMD moving)" % (sum(map(moving, w_beacons)), len(w_beacons)),
          sum(map(moving, w_beacons)) >= len(w_beacons) // 2 > 0)
    check("wifi-silent-channel-is-not-a-dead-feeder (%d of %d WHEEL_CMD moving, RSSI stale in none of %d STATUS)"
          % (n_mov, len(w_silent), len(s_silent)),
          n_mov >= len(w_silent) // 2 > 0 and s_silent and not any(map(stale, s_silent)))
    check("wifi-hung-feeder-stops-the-wheels (RSSI stale and Stop at the first step after 150 ms: %.0f and %.0f ms "
          "after the last heartbeat; then %d WHEEL_CMD all Stop at 0, %d STATUS all RSSI stale)"
          % (((first_stale or 0) - hang0) / 1e3, ((first_stop or 0) - hang0) / 1e3, len(w_hung), len(s_hung)),
          first_stale is not None and first_stale - hang0 > TIMEOUT_US - 5000 and after is not None
          and first_stale <= after
          and first_stop is not None and first_stop <= first_stale
          and len(w_hung) >= 10 and not any(map(moving, w_hung)) and all(s["Stop"] == "1" for s in w_hung)
          and all(map(stale, s_hung)))
    check("wifi-wheels-drive-again-after-the-hang (%d of %d WHEEL_CMD moving)"
          % (sum(map(moving, w_back)), len(w_back)), sum(map(moving, w_back)) >= 1)
    st = stalls(pose)
    if exit_status() != 0 and st:
        print("wifi-check-inconclusive: the VM stalled (poses stopped %s): timing says nothing"
              % ", ".join("%.0f ms" % (n / 1e3) for _, n in st))
        return INCONCLUSIVE
    return exit_status()


if __name__ == "__main__":
    sys.exit(main(sys.argv))
