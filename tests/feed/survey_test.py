#!/usr/bin/env python3
"""rfseek-feed --list against tshark (docs/FEEDER.md, "Survey").

For each capture, tshark's own fields are aggregated here per transmitter (wlan.ta):
frames, frames with radiotap.dbm_antsignal, their mean (2 decimals), min and max, the
earliest and latest frame.time_epoch, and the first non-hidden wlan.ssid of its beacons
and probe responses (tshark prints it in hex; escaped here as documented). The table
--list prints must equal it row for row, in its order (most frames first, ties by
address). Then --mac: the filtered table, and a MAC that sent nothing: the header only,
one warning line, exit status 3 (also in the plain TSV mode).

usage: survey_test.py FEED CAPTURE...
"""
import os
import struct
import subprocess
import sys
import tempfile
from decimal import Decimal

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pcap_build  # noqa: E402

HEADER = "mac\tframes\tdbm_frames\tmean_dbm\tmin_dbm\tmax_dbm\tfirst_epoch\tlast_epoch\tssid"
BEACON, PROBE_RESP = 0x0008, 0x0005
fails = 0


def report(ok, name, why=""):
    global fails
    print("%s %s%s" % ("PASS" if ok else "FAIL", name, "" if ok or not why else ": " + why))
    fails += 0 if ok else 1


def escape(raw):
    return "".join(chr(b) if 0x20 <= b <= 0x7E and b != 0x5C else "\\x%02x" % b for b in raw)


def tshark_table(cap, macs=None):
    out = subprocess.run(["tshark", "-r", cap, "-T", "fields", "-E", "occurrence=f", "-e", "wlan.ta",
                          "-e", "radiotap.dbm_antsignal", "-e", "frame.time_epoch",
                          "-e", "wlan.fc.type_subtype", "-e", "wlan.ssid"],
                         capture_output=True, text=True, check=True).stdout
    tx = {}
    for line in out.splitlines():
        ta, dbm, t, st, ssid = (line.split("\t") + [""] * 5)[:5]
        if not ta or (macs and ta not in macs):
            continue
        e = tx.setdefault(ta, {"n": 0, "dbm": [], "t": [], "ssid": None})
        e["n"] += 1
        e["t"].append(Decimal(t))
        if dbm:
            e["dbm"].append(int(dbm))
        if st and int(st, 16) in (BEACON, PROBE_RESP) and ssid not in ("", "<MISSING>") and e["ssid"] is None:
            raw = bytes.fromhex(ssid)
            if any(raw):
                e["ssid"] = escape(raw)
    rows = []
    for ta, e in sorted(tx.items(), key=lambda kv: (-kv[1]["n"], kv[0])):
        d = e["dbm"]
        stats = ["%.2f" % (sum(d) / len(d)), str(min(d)), str(max(d))] if d else ["", "", ""]
        rows.append("\t".join([ta, str(e["n"]), str(len(d))] + stats +
                              [format(min(e["t"]), ".9f"), format(max(e["t"]), ".9f"), e["ssid"] or ""]))
    return rows


def ssid_capture(path):
    """Beacons and probe responses with awkward SSIDs, written byte by byte: a hidden network
    (an empty SSID, then 4 zero bytes) named later by its probe response; a tab, a backslash
    and a non-ASCII byte; the 32-byte maximum; one over it (shown whole, as tshark does)."""
    def mgmt(t_us, subtype, mac, ssid, dbm=-50):
        rt = struct.pack("<BBHI", 0, 0, 9, 0x20) + struct.pack("<b", dbm)
        hdr = struct.pack("<BB", subtype << 4, 0) + b"\0\0" + b"\xff" * 6 + mac + mac + b"\0\0"
        body = b"\0" * 8 + struct.pack("<HH", 100, 0x0431) + bytes([0, len(ssid)]) + ssid + b"\x01\x01\x82"
        data = rt + hdr + body
        return struct.pack("<IIII", t_us // 1000000, t_us % 1000000, len(data), len(data)) + data
    a, b, c, d = (bytes.fromhex(x) for x in ("02aa00000001", "02aa00000002", "02aa00000003", "02aa00000004"))
    pcap_build.write(path, [mgmt(1_700_000_000_000_000, 8, a, b""), mgmt(1_700_000_000_100_000, 8, a, b"\0" * 4),
                            mgmt(1_700_000_000_200_000, 5, a, b"lab net", -61),
                            mgmt(1_700_000_000_300_000, 8, a, b"other"),
                            mgmt(1_700_000_000_400_000, 8, b, b"a\tb\\c\xff"),
                            mgmt(1_700_000_000_500_000, 8, c, b"x" * 32), mgmt(1_700_000_000_600_000, 8, d, b"y" * 33),
                            pcap_build.record(1_700_000_000_700_000, d, 1, -70)])


def feed(exe, *args):
    return subprocess.run([exe] + list(args), capture_output=True, text=True)


def main(argv):
    if len(argv) < 3:
        print(__doc__.strip())
        return 2
    exe, caps = argv[1], argv[2:]
    tmp = tempfile.mkdtemp(prefix="rfs_survey_")
    ssids = os.path.join(tmp, "ssids.pcap")
    ssid_capture(ssids)
    caps = caps + [ssids]
    total_rows = total_frames = 0
    for cap in caps:
        name = os.path.basename(cap)
        want = tshark_table(cap)
        r = feed(exe, cap, "--list")
        got = r.stdout.splitlines()
        ok = r.returncode == 0 and got[:1] == [HEADER] and got[1:] == want
        report(ok, "survey %s: %d transmitters, %d frames equal tshark's" %
               (name, len(want), sum(int(w.split("\t")[1]) for w in want)),
               "exit %d, %s" % (r.returncode, next((("ours %r, tshark %r" % (a, b)) for a, b in
                                                    zip(got[1:] + [""] * len(want), want) if a != b),
                                                   "%d rows vs %d" % (len(got) - 1, len(want)))))
        total_rows += len(want)
        total_frames += sum(int(w.split("\t")[1]) for w in want)
        if not want:
            continue
        # --mac keeps those transmitters only, in the same order.
        pick = [w.split("\t")[0] for w in want[-2:]]
        r = feed(exe, cap, "--list", *sum((["--mac", m] for m in pick), []))
        report(r.returncode == 0 and r.stdout.splitlines() == [HEADER] + tshark_table(cap, set(pick)),
               "survey %s --mac %s" % (name, " ".join(pick)), "exit %d" % r.returncode)
    # A MAC that sent nothing: complete output (the header), one warning, exit 3.
    cap = caps[0]
    nobody = "02:00:5e:00:00:99"
    r = feed(exe, cap, "--list", "--mac", nobody)
    report(r.returncode == 3 and r.stdout == HEADER + "\n" and
           r.stderr == "rfseek-feed: warning: %s: no frame from %s\n" % (cap, nobody),
           "survey-unheard-mac (exit 3, header only, one warning)", "exit %d, %r" % (r.returncode, r.stderr))
    known = tshark_table(cap)[0].split("\t")[0]
    r = feed(exe, cap, "--mac", known, "--mac", nobody.upper())
    report(r.returncode == 3 and r.stdout != "" and r.stderr.count("\n") == 1 and nobody in r.stderr,
           "tsv-unheard-mac (exit 3, the other's lines kept)", "exit %d, %r" % (r.returncode, r.stderr))
    r = feed(exe, cap, "--mac", known)
    report(r.returncode == 0 and r.stderr == "", "tsv-heard-mac (exit 0, no warning)")
    r = feed(exe, cap, "--list", "--live")
    report(r.returncode == 2 and r.stderr.count("\n") == 1, "survey-not-live (exit 2)")
    r = feed(exe, ssids, "--list")
    names = [ln.split("\t")[-1] for ln in r.stdout.splitlines()[1:]]
    report(names == ["lab net", "y" * 33, "a\\x09b\\x5cc\\xff", "x" * 32],
           "survey-ssids (hidden then named, escaped, 32 and 33 bytes)", repr(names))
    os.remove(ssids)
    os.rmdir(tmp)
    report(fails == 0 and total_rows >= 10, "survey: %d captures, %d transmitters, %d frames"
           % (len(caps), total_rows, total_frames), "%d failures" % fails)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
