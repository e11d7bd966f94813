#!/usr/bin/env bash
# test_models_cli.sh BUILD - the model and the target chosen by configuration, the same way
# in every program: rfseek-sim --model / `model:` / `target: pdr`, rfseek-feed
# --model / --target (PDR from a real capture's sequence numbers, checked against tshark),
# rfseekd --model. Bad values: one error line, non-zero exit. Prints PASS/FAIL lines.
set -u
b=${1:?usage: test_models_cli.sh BUILD}
sim=$b/bin/rfseek-sim
feed=$b/feed/asan/rfseek-feed
[ -x "$feed" ] || feed=$b/bin/rfseek-feed
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
. "$(dirname "$0")/../lib/checks.sh"
. "$(dirname "$0")/../lib/qemu.sh"
one_line() { [ "$(wc -l <"$1")" -eq 1 ] && grep -q "$2" "$1"; }
field() { /usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$1" "$2"; }

# --- rfseek-sim: every model by --model, in the open hall --------------------------------
for m in ridge mlp knn radius pathloss; do
    "$sim" scenarios/open.yaml --seed 2 --model "$m" --out "$tmp/sim-$m" 2>"$tmp/e"
    rc=$?
    check "sim-model-$m" '[ $rc -eq 0 ] && [ "$(field "$tmp/sim-$m/summary.json" model)" = "$m" ] && [ "$(field "$tmp/sim-$m/summary.json" iterations)" -gt 2 ]'
done
# Different models make different decisions on the same seed (the option is not ignored).
check sim-models-differ '! cmp -s <(cut -f2-7 "$tmp/sim-ridge/log.tsv") <(cut -f2-7 "$tmp/sim-mlp/log.tsv") && ! cmp -s <(cut -f2-7 "$tmp/sim-ridge/log.tsv") <(cut -f2-7 "$tmp/sim-knn/log.tsv")'

# The scenario's model: key, and --model overriding it.
sed -e "s|^map: |map: $PWD/scenarios/|" -e 's/^seed: 1$/seed: 2\nmodel: mlp/' scenarios/open.yaml >"$tmp/open-mlp.yaml"
"$sim" "$tmp/open-mlp.yaml" --out "$tmp/key-mlp" 2>"$tmp/e"
check sim-model-key '[ $? -eq 0 ] && [ "$(field "$tmp/key-mlp/summary.json" model)" = mlp ] && cmp -s "$tmp/key-mlp/log.tsv" "$tmp/sim-mlp/log.tsv"'
"$sim" "$tmp/open-mlp.yaml" --model knn --out "$tmp/key-knn" 2>"$tmp/e"
check sim-model-option-overrides-key '[ $? -eq 0 ] && [ "$(field "$tmp/key-knn/summary.json" model)" = knn ]'

# Bad models and targets: one line naming the key or option, exit 1, nothing written.
sed -e "s|^map: |map: $PWD/scenarios/|" -e 's/^seed: 1$/seed: 1\nmodel: svm/' scenarios/open.yaml >"$tmp/bad-model.yaml"
"$sim" "$tmp/bad-model.yaml" --out "$tmp/no1" >"$tmp/o" 2>"$tmp/e"
check sim-model-key-unknown '[ $? -eq 1 ] && one_line "$tmp/e" "model: .svm. is not a known model (ridge, mlp, knn, radius, pathloss)" && [ ! -e "$tmp/no1" ]'
"$sim" scenarios/open.yaml --model "" >"$tmp/o" 2>"$tmp/e"
check sim-model-empty '[ $? -eq 1 ] && one_line "$tmp/e" "^rfseek-sim: --model: expected a name"'
"$sim" scenarios/open.yaml --model MLP >"$tmp/o" 2>"$tmp/e"
check sim-model-case '[ $? -eq 1 ] && one_line "$tmp/e" "^rfseek-sim: --model: unknown .MLP."'
sed -e "s|^map: |map: $PWD/scenarios/|" -e 's/^target: pdr$/target: snr/' scenarios/pdr.yaml >"$tmp/bad-target.yaml"
"$sim" "$tmp/bad-target.yaml" >"$tmp/o" 2>"$tmp/e"
check sim-target-unknown '[ $? -eq 1 ] && one_line "$tmp/e" "target: .snr. is not rssi, bridge or pdr"'
sed -e "s|^map: |map: $PWD/scenarios/|" -e 's/^target: bridge$/target: pdr/' scenarios/bridge.yaml >"$tmp/pdr2.yaml"
"$sim" "$tmp/pdr2.yaml" >"$tmp/o" 2>"$tmp/e"
check sim-target-pdr-two-sources '[ $? -eq 1 ] && one_line "$tmp/e" "target: pdr needs exactly 1 source"'

# --- target: pdr in the simulator ---------------------------------------------------------
# Seeking the packet delivery ratio: 19 of seeds 1..20 reach the node; of 1..10, at least 9.
"$sim" scenarios/pdr.yaml --seeds 1..10 --jobs 2 --quiet --out "$tmp/pdr-runs" 2>"$tmp/e"
check sim-pdr-reaches-9-of-10-seeds '[ $? -eq 0 ] && [ "$(awk -F"\t" "NR > 1 && \$2 == 1" "$tmp/pdr-runs/runs.tsv" | wc -l)" -ge 9 ]'
"$sim" scenarios/pdr.yaml --seed 1 --out "$tmp/pdr1" 2>"$tmp/e"
check sim-pdr-summary '[ $? -eq 0 ] && [ "$(field "$tmp/pdr1/summary.json" target)" = pdr ]'
# The seeker saw percentages (log mean column, 0..100) that rise towards the source, and
# the simulated link really lost packets (the ratio is not 100 % everywhere).
check sim-pdr-values '/usr/bin/python3 - "$tmp/pdr1" <<"PY"
import csv, json, sys
d = sys.argv[1]
rows = [r for r in csv.DictReader(open(d + "/log.tsv"), delimiter="\t") if r["mean_db"] != "nan"]
m = [float(r["mean_db"]) for r in rows]
s = json.load(open(d + "/summary.json"))
ok = len(m) >= 6 and all(0.0 <= v <= 100.0 for v in m) and sum(m[-3:]) / 3 > sum(m[:3]) / 3 + 10
ok = ok and s["packets_received"] < 0.9 * s["packets_sent"]
sys.exit(0 if ok else 1)
PY'
# The same run with the RSSI target seeks dBm (negative means): the key switches the target.
sed -e "s|^map: |map: $PWD/scenarios/|" -e 's/^target: pdr$/target: rssi/' scenarios/pdr.yaml >"$tmp/pdr-as-rssi.yaml"
"$sim" "$tmp/pdr-as-rssi.yaml" --seed 1 --out "$tmp/rssi1" 2>"$tmp/e"
check sim-rssi-target-dbm '[ $? -eq 0 ] && awk -F"\t" "NR > 1 && \$12 != \"nan\" && \$12 >= 0 {bad = 1} END {exit bad}" "$tmp/rssi1/log.tsv"'

# --- rfseek-feed: --model and --target in replay -------------------------------------------
# Real captures: a station with gaps in its numbers (exthdr), two with gaps, resyncs
# (numbers stepping back) and wrap-arounds (wpa2). The poses cover each capture's span
# and stay 7 m from the goal, so no replay stops early.
poses() {  # poses T0_US SECONDS > CSV: a slow drive east in the open hall, 10 Hz
    /usr/bin/python3 -c "
import sys
t0, n = int(sys.argv[1]), int(float(sys.argv[2]) * 10)
print('t_us,x_m,y_m,theta_rad')
for k in range(n + 1):
    print('%d,%.4f,10.000,0.0' % (t0 + k * 100000, 5 + 3.0 * k / n))" "$1" "$2"
}
for run in "ieee802.11_exthdr.pcap 90:a4:de:c0:46:11 1366203553000000 6" \
           "wpa2linkuppassphraseiswireshark.pcap 40:40:a7:50:73:db 1626136919000000 95" \
           "wpa2linkuppassphraseiswireshark.pcap 50:0f:80:70:18:d0 1626136919000000 95"; do
    set -- $run
    cap=tests/data/captures/$1 mac=$2 t0=$3
    poses "$t0" "$4" >"$tmp/poses-$mac.csv"
    "$feed" "$cap" --pose "$tmp/poses-$mac.csv" --scenario scenarios/open.yaml --mac "$mac" --target pdr \
        --model mlp --out "$tmp/feed-$mac" 2>"$tmp/e"
    check "feed-pdr-runs-$mac" '[ $? -eq 0 ] && [ ! -s "$tmp/e" ] && [ "$(field "$tmp/feed-$mac/summary.json" target)" = pdr ] && [ "$(field "$tmp/feed-$mac/summary.json" model)" = mlp ]'
    /usr/bin/python3 tests/host_sim/pdr_replay_check.py "$cap" "$mac" "$tmp/feed-$mac/samples.tsv" "$t0" \
        | sed "s/^\(PASS\|FAIL\) /\1 feed-pdr-$mac: /"
    [ "${PIPESTATUS[0]}" -eq 0 ] || fails=$((fails + 1))
done
cap=tests/data/captures/ieee802.11_exthdr.pcap
poses 1366203553000000 6 >"$tmp/poses.csv"
"$feed" "$cap" --pose "$tmp/poses.csv" --scenario scenarios/open.yaml --mac 90:a4:de:c0:46:11 \
    --model knn --out "$tmp/feed-knn" 2>"$tmp/e"
check feed-model-rssi '[ $? -eq 0 ] && [ "$(field "$tmp/feed-knn/summary.json" model)" = knn ] && [ "$(field "$tmp/feed-knn/summary.json" target)" = rssi ] && head -1 "$tmp/feed-knn/samples.tsv" | grep -q "	dbm$"'
"$feed" "$cap" --pose "$tmp/poses.csv" --scenario scenarios/open.yaml --target snr --out "$tmp/no2" >"$tmp/o" 2>"$tmp/e"
check feed-target-unknown '[ $? -eq 2 ] && one_line "$tmp/e" "^rfseek-feed: --target: unknown .snr. (rssi, pdr)" && [ ! -e "$tmp/no2" ]'
"$feed" "$cap" --pose "$tmp/poses.csv" --scenario scenarios/open.yaml --model svm --out "$tmp/no3" >"$tmp/o" 2>"$tmp/e"
check feed-model-unknown '[ $? -eq 2 ] && one_line "$tmp/e" "^rfseek-feed: --model: unknown .svm." && [ ! -e "$tmp/no3" ]'
"$feed" "$cap" --mac 90:a4:de:c0:46:11 --target pdr >"$tmp/o" 2>"$tmp/e"
check feed-target-needs-pose '[ $? -eq 2 ] && one_line "$tmp/e" "only go with --pose"'
"$feed" "$cap" --pose "$tmp/poses.csv" --scenario scenarios/bridge.yaml --target pdr --out "$tmp/no4" >"$tmp/o" 2>"$tmp/e"
check feed-target-pdr-two-sources '[ $? -eq 2 ] && one_line "$tmp/e" "^rfseek-feed: --target: pdr needs exactly 1 source" && [ ! -e "$tmp/no4" ]'

# --- firmware: the model by configuration (CFG record), on the host and the Cortex-M4 -----
qemu() { qemu_play "$b/firmware/qemu.elf" "$@" 300; } # qemu DIR IN OUT; console on stdout
rec=$b/bin/rfseek-record rpl=$b/bin/rfseek-replay
"$rec" scenarios/default.yaml -o "$tmp/mlp.rfsr" --live-out "$tmp/mlp-live.rfso" --max-time 60 \
    --fit-budget 2500 --model mlp >/dev/null 2>"$tmp/e"
check fw-record-mlp '[ $? -eq 0 ] && "$rpl" --print "$tmp/mlp.rfsr" | head -1 | grep -q "model=mlp"'
"$rec" scenarios/default.yaml -o "$tmp/ridge.rfsr" --live-out "$tmp/ridge-live.rfso" --max-time 60 \
    --fit-budget 2500 >/dev/null 2>"$tmp/e"
check fw-record-ridge-v1-cfg '[ $? -eq 0 ] && ! "$rpl" --print "$tmp/ridge.rfsr" | head -1 | grep -q model='
"$rpl" "$tmp/mlp.rfsr" -o "$tmp/mlp-host.rfso" 2>"$tmp/e"
check fw-mlp-host-equals-live '[ $? -eq 0 ] && cmp -s "$tmp/mlp-host.rfso" "$tmp/mlp-live.rfso"'
check fw-mlp-decides-unlike-ridge '[ "$("$rpl" --print "$tmp/mlp-host.rfso" | grep -c ^DECISION)" -ge 3 ] && ! cmp -s <("$rpl" --print "$tmp/mlp-host.rfso" | grep ^DECISION) <("$rpl" --print "$tmp/ridge-live.rfso" | grep ^DECISION)'
qemu "$tmp" mlp.rfsr mlp-qemu.rfso >"$tmp/q.txt" 2>&1
check fw-mlp-qemu-bit-identical '[ $? -eq 0 ] && cmp -s "$tmp/mlp-qemu.rfso" "$tmp/mlp-host.rfso"'
"$rec" scenarios/default.yaml -o "$tmp/knn.rfsr" --max-time 5 --model knn >/dev/null 2>"$tmp/e"
"$rpl" "$tmp/knn.rfsr" -o "$tmp/knn-host.rfso" 2>"$tmp/e"
check fw-knn-host-runs '[ $? -eq 0 ] && [ -s "$tmp/knn-host.rfso" ]'
qemu "$tmp" knn.rfsr knn-qemu.rfso >"$tmp/q.txt" 2>&1
check fw-knn-qemu-refused '[ $? -eq 1 ] && one_line "$tmp/q.txt" "^rfseek-qemu: CFG model.s state is larger than the image holds"'
"$rec" scenarios/default.yaml -o "$tmp/no5.rfsr" --model svm >"$tmp/o" 2>"$tmp/e"
check fw-record-model-unknown '[ $? -eq 2 ] && one_line "$tmp/e" "^rfseek-record: --model: unknown .svm." && [ ! -e "$tmp/no5.rfsr" ]'
"$rec" scenarios/pdr.yaml -o "$tmp/no6.rfsr" >"$tmp/o" 2>"$tmp/e"
check fw-record-pdr-refused '[ $? -eq 1 ] && one_line "$tmp/e" "target: pdr is not available on the firmware" && [ ! -e "$tmp/no6.rfsr" ]'

# rfseekd --model: bad names, and a replayed LCM input through each model.
d=$b/bin/rfseekd tool=$b/tests/wire/lcm_tool
"$d" --map scenarios/maps/office.yaml --model svm >"$tmp/o" 2>"$tmp/e"
check rfseekd-model-unknown '[ $? -eq 2 ] && one_line "$tmp/e" "^rfseekd: --model: expected ridge, mlp, knn, radius or pathloss, got svm"'
"$d" --help | grep -q -- "--model NAME"
check rfseekd-help-model '[ $? -eq 0 ]'
"$d" --map scenarios/maps/office.yaml --model pathloss --p0-min loud >"$tmp/o" 2>"$tmp/e"
check rfseekd-p0-min-number '[ $? -eq 2 ] && one_line "$tmp/e" "^rfseekd: --p0-min: expected dBm in \[-200, 100\], got loud"'
"$d" --map scenarios/maps/office.yaml --model pathloss --p0-min -300 >"$tmp/o" 2>"$tmp/e"
check rfseekd-p0-min-range '[ $? -eq 2 ] && one_line "$tmp/e" "^rfseekd: --p0-min: expected dBm in \[-200, 100\], got -300"'
"$d" --map scenarios/maps/office.yaml --model ridge --p0-min -32 >"$tmp/o" 2>"$tmp/e"
check rfseekd-p0-min-not-pathloss '[ $? -eq 2 ] && one_line "$tmp/e" "^rfseekd: --p0-min: only with --model pathloss"'
"$d" --help | grep -q -- "--p0-min DBM"
check rfseekd-help-p0-min '[ $? -eq 0 ]'
"$d" --map scenarios/maps/office.yaml --strategy meta-global >"$tmp/o" 2>"$tmp/e"
check rfseekd-strategy-global '[ $? -eq 2 ] && one_line "$tmp/e" "^rfseekd: --strategy: expected meta, meta-path, fd-gradient, plane-gradient or chemotaxis, got meta-global"'
"$d" --map scenarios/maps/office.yaml --strategy Meta >"$tmp/o" 2>"$tmp/e"
check rfseekd-strategy-unknown '[ $? -eq 2 ] && one_line "$tmp/e" "^rfseekd: --strategy: expected .*, got Meta"'
"$d" --help | grep -q -- "--strategy NAME"
check rfseekd-help-strategy '[ $? -eq 0 ]'
if [ -x "$tool" ] && "$tool" mklog "$tmp/in.lcmlog"; then
    for m in ridge mlp knn; do
        "$d" --map scenarios/maps/office.yaml --replay "$tmp/in.lcmlog" --clock-lcm --model "$m" \
            >"$tmp/d-$m.txt" 2>"$tmp/d-$m.err"
        check "rfseekd-model-$m" '[ $? -eq 0 ] && grep -q "^rfseekd: 81 steps.*(strategy meta, model $m, fit budget 0, fit_early off)\$" "$tmp/d-$m.err" && [ -s "$tmp/d-$m.txt" ]'
    done
    for st in meta-path chemotaxis; do
        "$d" --map scenarios/maps/office.yaml --replay "$tmp/in.lcmlog" --clock-lcm --model pathloss \
            --strategy "$st" >"$tmp/s-$st.txt" 2>"$tmp/s-$st.err"
        check "rfseekd-strategy-$st" '[ $? -eq 0 ] && grep -q "^rfseekd: 81 steps.*(strategy $st, model pathloss, fit budget 0, fit_early off)\$" "$tmp/s-$st.err"'
    done
else
    echo "FAIL rfseekd-model-replay: $tool mklog unavailable"; fails=$((fails + 1))
fi

[ $fails -eq 0 ]
