#!/usr/bin/env bash
# Bad input to rfseek-feed (run on its ASan+UBSan build): damaged captures give one clear
# error line naming the file and a non-zero exit, or a counted skip; never a crash.
# usage: bad_input.sh FEED GENDIR   (GENDIR from scripts/gen_captures.py)
set -uo pipefail
feed=$1 gen=$2
mal=tests/data/captures/malformed
fail=0
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
mac=02:aa:bb:cc:00:01
# expect NAME RC STDERR_REGEX -- ARGS...
expect() {
    local name=$1 want_rc=$2 re=$3; shift 4
    "$feed" "$@" >"$tmp/out" 2>"$tmp/err"
    local rc=$?
    local lines; lines=$(grep -c . "$tmp/err")
    if grep -qE 'Sanitizer|runtime error' "$tmp/err"; then
        echo "FAIL $name: sanitizer report"; head -5 "$tmp/err"; fail=1
    elif [ "$rc" -ne 0 ] && [ "$rc" -ne 3 ] && [ "$lines" -ne 1 ]; then
        echo "FAIL $name: $lines stderr lines, want one"; head -3 "$tmp/err"; fail=1
    elif [ "$rc" -eq 3 ] && [ "$(grep -c '^rfseek-feed: warning: .*: no frame from ' "$tmp/err")" -ne 1 ]; then
        echo "FAIL $name: exit 3 without its one warning line"; head -3 "$tmp/err"; fail=1
    elif [ "$rc" -ne "$want_rc" ]; then
        echo "FAIL $name: exit $rc, want $want_rc"; head -3 "$tmp/err"; fail=1
    elif ! grep -qE -- "$re" "$tmp/err"; then
        echo "FAIL $name: stderr does not match /$re/:"; head -3 "$tmp/err"; fail=1
    else
        echo "PASS $name: exit $rc, $(head -1 "$tmp/err")"
    fi
}
expect empty 1 "empty.pcap: cannot read capture: truncated dump file" -- "$gen/bad/empty.pcap" --mac $mac
expect short_file_header 1 "short_header.pcap: cannot read capture: truncated dump file" -- "$gen/bad/short_header.pcap" --mac $mac
expect not_a_capture 1 "not_a_capture.pcap: cannot read capture: unknown file format" -- "$gen/bad/not_a_capture.pcap" --mac $mac
expect linktype_105 1 "linktype_105.pcap: link type 105 \(IEEE802_11\) is not 127" -- "$gen/bad/linktype_105.pcap" --mac $mac
expect linktype_1 1 "linktype_1.pcap: link type 1 \(EN10MB\) is not 127" -- "$gen/bad/linktype_1.pcap" --mac $mac
expect cut_record 1 "cut_record.pcap: truncated dump file.*after 19 packets" -- "$gen/bad/cut_record.pcap" --mac $mac
expect cut_record_header 1 "cut_record_header.pcap: truncated dump file.*after 0 packets" -- "$gen/bad/cut_record_header.pcap" --mac $mac
expect missing_file 1 "nonexistent.pcap: cannot read capture: .*No such file" -- "$tmp/nonexistent.pcap" --mac $mac
# live: the same link-type rule on an interface (loopback: Ethernet framing; without the
# privilege to capture, the activation error instead), and an interface that does not exist
expect live_loopback 1 "lo: (link type 1 \(EN10MB\) is not 127 .*: not a monitor-mode interface|cannot activate interface: .*(ermission|not permitted))" -- lo --live --mac $mac
expect live_no_interface 1 "nosuchif0: cannot activate interface" -- nosuchif0 --live --mac $mac
# --lcm (publishing to the controller): the same interface errors; a bad URL is refused
# before the interface is opened; liblcm's own complaint folded into the one line
expect lcm_no_interface 1 "nosuchif0: cannot activate interface" -- nosuchif0 --live --lcm memq:// --mac $mac
expect lcm_loopback 1 "lo: (link type 1 \(EN10MB\) is not 127 .*: not a monitor-mode interface|cannot activate interface: .*(ermission|not permitted))" -- lo --live --lcm memq:// --mac $mac
expect lcm_bad_provider 1 "lcm: foo://: cannot open this provider.*liblcm: .*foo" -- nosuchif0 --live --lcm foo:// --mac $mac
expect lcm_bad_address 1 "lcm: udpm://300.1.2.3:7667: cannot open this provider" -- nosuchif0 --live --lcm udpm://300.1.2.3:7667 --mac $mac
expect lcm_newline 1 "lcm: udpm://\?x: cannot open this provider" -- nosuchif0 --live --lcm $'udpm://\nx' --mac $mac
expect lcm_needs_live 2 "--lcm publishes a live interface: needs --live" -- nosuchif0 --lcm memq:// --mac $mac
expect lcm_not_with_output 2 "not with --output" -- nosuchif0 --live --lcm memq:// --output "$tmp/x.tsv" --mac $mac
expect lcm_missing_value 2 "--lcm needs a value" -- nosuchif0 --live --mac $mac --lcm
# the 11 records of radiotap_lies: each lie counted, 3 usable frames with a signal
expect radiotap_lies 0 "11 packets, 3 lines; 3 note: a field runs past it_len; 1 skipped: fewer than 8 bytes.*; 1 skipped: radiotap version byte is not 0; 2 skipped: radiotap it_len .*; 1 skipped: radiotap present bitmaps run past it_len; 1 skipped: no 802.11 header; 1 skipped: no source address; 1 skipped: matching source without dBm signal" -- "$gen/bad/radiotap_lies.pcap" --mac $mac --stats
# (a --mac no frame came from: a warning line and exit 3, the output complete)
for f in "$mal"/*.pcap; do
    expect "malformed/$(basename "$f")" 3 "1 packets, 0 lines; 1 skipped: radiotap version byte is not 0; 1 note: cut by the snap length" -- "$f" --mac 90:a4:de:c0:46:11 --stats
done
# options
expect no_args 2 "no CAPTURE given" --
expect no_mac 2 "no --mac given" -- "$gen/ds.pcap"
expect bad_mac 2 "--mac: '02:aa:bb:cc:00' is not a MAC address" -- "$gen/ds.pcap" --mac 02:aa:bb:cc:00
expect bad_mac_hex 2 "--mac: '02:aa:bb:cc:00:0g' is not a MAC address" -- "$gen/ds.pcap" --mac 02:aa:bb:cc:00:0g
expect bad_format 2 "--format: 'csv' is not supported" -- "$gen/ds.pcap" --mac $mac --format csv
expect unknown_option 2 "unknown option '--frobnicate'" -- "$gen/ds.pcap" --mac $mac --frobnicate
# "" as a file or URL: refused before any work (--output "" was read through, then not
# renamed; --lcm "" would be liblcm's default provider, udpm)
expect empty_output 2 "^rfseek-feed: --output: empty value" -- "$gen/ds.pcap" --mac $mac --output ""
expect empty_lcm 2 "^rfseek-feed: --lcm: empty value" -- lo --live --lcm "" --mac $mac
expect empty_out 2 "^rfseek-feed: --out: empty value" -- "$gen/ds.pcap" --pose "$tmp/p.csv" --scenario scenarios/default.yaml --out ""
expect mac_missing_value 2 "--mac needs a value" -- "$gen/ds.pcap" --mac
expect seed_newline 2 "--seed: '1\\?2' is not a non-negative integer" -- "$gen/ds.pcap" --mac $mac --pose x --seed $'1\n2'
"$feed" --help | grep -q '^usage: rfseek-feed CAPTURE --mac MAC' && echo "PASS help" || { echo "FAIL help"; fail=1; }
# --output: written through a temporary file, nothing left behind on failure
"$feed" "$gen/ds.pcap" --mac $mac --output "$tmp/ok.tsv" && [ "$(wc -l < "$tmp/ok.tsv")" -eq 80 ] && [ ! -e "$tmp/ok.tsv.tmp" ] \
    && echo "PASS output: 80 lines in the file, no temporary left" || { echo "FAIL output"; fail=1; }
"$feed" "$gen/bad/cut_record.pcap" --mac $mac --output "$tmp/bad.tsv" 2>/dev/null
if [ $? -ne 0 ] && [ ! -e "$tmp/bad.tsv" ] && [ ! -e "$tmp/bad.tsv.tmp" ]; then echo "PASS output_on_error: no file written"
else echo "FAIL output_on_error: a file was left"; fail=1; fi
# Timestamps at the edges of the formats, printed as tshark prints frame.time_epoch: a
# classic pcap's seconds are unsigned 32-bit (2^31 and 2^32 - 1), a pcapng's timestamp
# unsigned 64-bit in units of if_tsresol (9: ns, 2^64 - 1; 0x94: 2^-20 s).
PYTHONPATH=tests/feed /usr/bin/python3 - "$tmp" <<'PY'
import struct, sys
import pcap_build
d = sys.argv[1]
mac = bytes.fromhex("02aabbcc0001")
pcap_build.write(d + "/ts_2e31.pcap", [pcap_build.record(2**31 * 10**6, mac, 1, -40),
                                       pcap_build.record((2**32 - 1) * 10**6 + 999999, mac, 2, -41)])
frame = pcap_build.record(0, mac, 3, -42)[16:]
def block(kind, body):
    body += b"\0" * (-len(body) % 4)
    return struct.pack("<II", kind, len(body) + 12) + body + struct.pack("<I", len(body) + 12)
def pcapng(path, tsresol, ts):
    shb = block(0x0A0D0D0A, struct.pack("<IHHq", 0x1A2B3C4D, 1, 0, -1))
    opt = struct.pack("<HHB3x", 9, 1, tsresol) + struct.pack("<HH", 0, 0)
    idb = block(1, struct.pack("<HHI", 127, 0, 65535) + opt)
    epb = block(6, struct.pack("<IIIII", 0, ts >> 32, ts & 0xFFFFFFFF, len(frame), len(frame)) + frame)
    open(path, "wb").write(shb + idb + epb)
pcap_build.write(d + "/frac_2e31.pcap", [struct.pack("<IIII", 5, 2**31, len(frame), len(frame)) + frame])
pcap_build.write(d + "/frac_1s.pcap", [struct.pack("<IIII", 5, 10**6, len(frame), len(frame)) + frame])
pcapng(d + "/ts_res9_max.pcapng", 9, 2**64 - 1)
pcapng(d + "/ts_res2_20.pcapng", 0x94, (1700000000 << 20) + 524288 + 3)
PY
[ $? -eq 0 ] || { echo "FAIL edge-captures: the Python writer failed"; fail=1; }
# expect_lines NAME FILE LINE...: rfseek-feed prints exactly these lines, without a
# sanitizer report; and tshark's frame.time_epoch (the independent reader) agrees.
expect_lines() {
    local name=$1 file=$2; shift 2
    local want; want=$(printf '%s\n' "$@")
    "$feed" "$file" --mac $mac >"$tmp/out" 2>"$tmp/err"
    local rc=$?
    if [ $rc -ne 0 ] || grep -qE 'Sanitizer|runtime error' "$tmp/err"; then
        echo "FAIL $name: exit $rc: $(head -3 "$tmp/err")"; fail=1
    elif [ "$(cat "$tmp/out")" != "$want" ]; then
        echo "FAIL $name: printed '$(cat "$tmp/out")', want '$want'"; fail=1
    elif [ "$(tshark -r "$file" -T fields -e frame.time_epoch 2>/dev/null)" != "$(printf '%s\n' "$@" | cut -f1)" ]; then
        echo "FAIL $name: tshark reads $(tshark -r "$file" -T fields -e frame.time_epoch 2>&1 | tr '\n' ' ')"; fail=1
    else
        echo "PASS $name: $(tr '\n' ' ' <"$tmp/out")"
    fi
}
expect_lines ts_pcap_2e31 "$tmp/ts_2e31.pcap" $'2147483648.000000000\t02:aa:bb:cc:00:01\t-40' \
    $'4294967295.999999000\t02:aa:bb:cc:00:01\t-41'
expect_lines ts_pcapng_res9_max "$tmp/ts_res9_max.pcapng" $'18446744073.709551615\t02:aa:bb:cc:00:01\t-42'
expect_lines ts_pcapng_res2_20 "$tmp/ts_res2_20.pcapng" $'1700000000.500002861\t02:aa:bb:cc:00:01\t-42'
# a classic record's fraction field of one second or more is damage, not time
expect frac_2e31 1 "frac_2e31.pcap: damaged record: timestamp fraction not below one second \(after 0 packets\)" -- "$tmp/frac_2e31.pcap" --mac $mac
expect frac_1s 1 "frac_1s.pcap: damaged record: timestamp fraction not below one second \(after 0 packets\)" -- "$tmp/frac_1s.pcap" --mac $mac
exit $fail
