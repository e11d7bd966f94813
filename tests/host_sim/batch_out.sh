#!/usr/bin/env bash
# batch_out.sh - rfseek-sim's outputs under stress: a seed range at the top of uint64 (one
# seed, no wrap) and one too large (refused), stdout on /dev/full (single and batch), a
# full disk (a 200 KB tmpfs: one error line, nothing left), and a batch interrupted by
# SIGINT / SIGTERM / SIGKILL then continued with --resume to the very table an
# uninterrupted batch writes (and one, two or three workers the same table);
# scripts/merge_runs.py on an interrupted directory names the missing seeds.
#   tests/host_sim/batch_out.sh build/bin/rfseek-sim        (from the repository root)
set -uo pipefail
SIM=${1:?usage: batch_out.sh path/to/rfseek-sim}
T=$(mktemp -d /tmp/rfs_batch_out.XXXXXX)
trap 'mountpoint -q "$T/full" && umount "$T/full"; rm -rf -- "$T"' EXIT
. "$(dirname "$0")/../lib/checks.sh"
SCN=scenarios/default.yaml

# one_line NAME RC TEXT: the last command's exit status was RC, T/err is one line with TEXT.
one_line() {
    local name=$1 rc=$2 text=$3 lines
    lines=$(wc -l <"$T/err")
    if [ "$rc" -ne 1 ]; then fail "$name" "exit $rc"
    elif [ "$lines" -ne 1 ]; then fail "$name" "$lines stderr lines: $(head -c 300 "$T/err")"
    elif ! grep -qF -- "$text" "$T/err"; then fail "$name" "stderr '$(cat "$T/err")' lacks '$text'"
    else pass "$name"; fi
}

# --- seed ranges -------------------------------------------------------------------------
M=18446744073709551615
"$SIM" $SCN --seeds $M..$M --quiet >"$T/top.tsv" 2>"$T/err"
rc=$?
check "seeds-top-one-row" '[ $rc -eq 0 ] && [ $(wc -l <"$T/top.tsv") -eq 2 ] && [ "$(cut -f1 "$T/top.tsv" | tail -1)" = $M ]'
"$SIM" $SCN --seeds 0..$M --quiet >"$T/all.tsv" 2>"$T/err"
one_line seeds-whole-range $? "is more than 1000000 seeds in one batch"
check "seeds-whole-range-no-table" '[ ! -s "$T/all.tsv" ]'
"$SIM" $SCN --seeds 1..1000001 --quiet >/dev/null 2>"$T/err"
one_line seeds-over-cap $? "more than 1000000 seeds"

# --- stdout on /dev/full -----------------------------------------------------------------
"$SIM" $SCN --seed 1 >/dev/full 2>"$T/err"
one_line stdout-full-single $? "rfseek-sim: stdout: No space left on device"
"$SIM" $SCN --seeds 1..2 --quiet >/dev/full 2>"$T/err"
one_line stdout-full-batch $? "rfseek-sim: stdout: No space left on device"
"$SIM" $SCN --seeds 1..2 --emit-jobs --out "$T/e" >/dev/full 2>"$T/err"
one_line stdout-full-emit-jobs $? "rfseek-sim: stdout: No space left on device"

# --- destinations checked before the run ---------------------------------------------------
"$SIM" $SCN --seed 1 --out "$T/no/such/out" 2>"$T/err"
one_line out-parent-missing $? "$T/no/such/out: No such file or directory"
"$SIM" $SCN --seed 1 --pcap "$T/no/x.pcap" 2>"$T/err"
one_line pcap-parent-missing $? "$T/no/x.pcap: No such file or directory"
cp $SCN "$T/s.yaml"
sed -i "s|^map: *|map: $PWD/scenarios/|" "$T/s.yaml" 2>/dev/null
ln -s "$T/s.yaml" "$T/link.pcap"
"$SIM" "$T/s.yaml" --seed 1 --pcap "$T/link.pcap" 2>"$T/err" >/dev/null
one_line pcap-is-the-scenario $? "is the input"

# --- a full disk ---------------------------------------------------------------------------
mkdir -p "$T/full"
if mount -t tmpfs -o size=200k tmpfs "$T/full" 2>/dev/null; then
    "$SIM" $SCN --seed 1 --out "$T/full/one" 2>"$T/err"
    one_line disk-full-single $? "No space left on device"
    check "disk-full-single-nothing-left" '[ -z "$(ls -A "$T/full")" ]'
    "$SIM" $SCN --seeds 1..4 --jobs 2 --quiet --out "$T/full/many" 2>"$T/err"
    one_line disk-full-batch $? "No space left on device"
    check "disk-full-batch-nothing-left" '[ -z "$(ls -A "$T/full")" ]'
    umount "$T/full"
else
    echo "SKIP disk-full: mount -t tmpfs not permitted"
fi

# --- interrupted and resumed batches -------------------------------------------------------
# interrupt SIG DIR [ARGS]: start 1..40 into DIR (with ARGS), signal it once 3 more seeds
# are finished.
interrupt() {
    local n0
    n0=$(cat "$2"/batch.state 2>/dev/null | wc -l)
    "$SIM" $SCN --seeds 1..40 --jobs 2 --quiet --out "$2" "${@:3}" 2>"$T/err" &
    local pid=$! n=0
    for _ in $(seq 600); do
        n=$(cat "$2".tmp-*/batch.state 2>/dev/null | wc -l)
        [ "$n" -ge $((n0 > 0 ? n0 + 3 : 4)) ] && break
        sleep 0.05
    done
    kill -"$1" $pid
    wait $pid
}
"$SIM" $SCN --seeds 1..40 --jobs 2 --quiet --out "$T/whole" 2>/dev/null
# Workers take runs as they come free: any number of them writes the single process's table.
"$SIM" $SCN --seeds 1..40 --quiet --out "$T/one" 2>/dev/null
"$SIM" $SCN --seeds 1..40 --jobs 3 --quiet --out "$T/three" 2>/dev/null
check "jobs-same-table" 'cmp "$T/one/runs.tsv" "$T/whole/runs.tsv" && cmp "$T/one/runs.tsv" "$T/three/runs.tsv"'
for sig in INT TERM; do
    d=$T/cut$sig
    interrupt $sig "$d"
    one_line "interrupt-$sig-one-line" $? "interrupted; the finished seeds are kept there, continue with --resume"
    done=$(($(wc -l <"$d/batch.state") - 1))
    ndirs=$(ls -d "$d"/seed-* | wc -l)
    check "interrupt-$sig-state" '[ -d "$d" ] && [ ! -e "$d/runs.tsv" ] && [ $done -ge 3 ] && [ $done -lt 40 ] && [ $ndirs -eq $done ]'
    check "interrupt-$sig-no-litter" '! compgen -G "$d.tmp-*" >/dev/null'
    check "interrupt-$sig-finished-complete" 'for s in $(tail -n +2 "$d/batch.state" | cut -f1); do [ -s "$d/seed-$s/summary.json" ] || exit 1; done'
    python3 scripts/merge_runs.py "$d" --out "$T/m.tsv" 2>"$T/err"
    one_line "merge-$sig-names-missing" $? "of 40 seeds missing"
    python3 scripts/merge_runs.py "$d" --out "$T/m.tsv" --allow-missing 2>"$T/err"
    check "merge-$sig-allow-missing" '[ $? -eq 0 ] && [ $(wc -l <"$T/m.tsv") -eq $((done + 1)) ]'
    "$SIM" $SCN --seeds 1..40 --jobs 2 --quiet --out "$d" --resume 2>"$T/err"
    check "resume-$sig" '[ $? -eq 0 ] && [ ! -s "$T/err" ] && cmp "$d/runs.tsv" "$T/whole/runs.tsv" && [ ! -e "$d/batch.state" ] && [ $(ls -d "$d"/seed-* | wc -l) -eq 40 ]'
    check "resume-$sig-seed-logs" 'diff -r "$d" "$T/whole" >/dev/null'
done
# SIGKILL: no handler runs. The batch's DIR.tmp-PID holds batch.state (written as the batch
# began, a row per finished seed) and is what --resume takes when DIR is missing; refused
# while that batch still runs, and when two killed batches are left; the workers end with
# their parent.
d=$T/cutKILL
"$SIM" $SCN --seeds 1..40 --jobs 2 --quiet --out "$d" 2>/dev/null &
pid=$!
for _ in $(seq 600); do
    [ "$(cat "$d".tmp-*/batch.state 2>/dev/null | wc -l)" -ge 4 ] && break
    sleep 0.05
done
"$SIM" $SCN --seeds 1..40 --quiet --out "$d" --resume 2>"$T/err"
one_line resume-KILL-still-running $? "its batch is still running (process $pid)"
{ kill -KILL $pid; wait $pid; } 2>/dev/null # (bash's "Killed" notice)
sleep 0.2
check "interrupt-KILL-workers-gone" '! pgrep -f -- "--out $d\$" >/dev/null'
check "interrupt-KILL-leaves-tmp" '[ ! -e "$d" ] && [ -f "$d.tmp-$pid/batch.state" ] && [ $(ls -d "$d".tmp-* | wc -l) -eq 1 ]'
cp -r "$d.tmp-$pid" "$d.tmp-2147483647" # a PID above pid_max: a process that cannot run
"$SIM" $SCN --seeds 1..40 --quiet --out "$d" --resume 2>"$T/err"
one_line resume-KILL-two-left $? "two killed batches"
rm -rf "$d.tmp-2147483647"
"$SIM" $SCN --seeds 1..40 --jobs 2 --quiet --out "$d" --resume 2>"$T/err"
check "resume-KILL" '[ $? -eq 0 ] && [ ! -s "$T/err" ] && cmp "$d/runs.tsv" "$T/whole/runs.tsv" && [ ! -e "$d/batch.state" ] && ! compgen -G "$d.tmp-*" >/dev/null'
check "resume-KILL-seed-logs" 'diff -r "$d" "$T/whole" >/dev/null'

# A row cut by SIGKILL is dropped from batch.state as the batch resumes, so rows appended
# after it are whole when that batch is interrupted and resumed again.
d=$T/cutrow
interrupt INT "$d"
todo=$(comm -23 <(seq 1 40 | sort) <(tail -n +2 "$d/batch.state" | cut -f1 | sort) | head -1)
printf '%s\t1\t12.5' "$todo" >>"$d/batch.state"
interrupt INT "$d" --resume
check "resume-cut-row-dropped" '! grep -q "12\.5[0-9]" "$d/batch.state" && [ "$(tail -c 1 "$d/batch.state" | od -An -c | tr -d " ")" = "\\n" ]'
"$SIM" $SCN --seeds 1..40 --jobs 2 --quiet --out "$d" --resume 2>"$T/err"
check "resume-cut-row-twice" '[ $? -eq 0 ] && [ ! -s "$T/err" ] && cmp "$d/runs.tsv" "$T/whole/runs.tsv"'

"$SIM" $SCN --seeds 1..40 --quiet --out "$T/whole" --resume 2>"$T/err"
one_line resume-finished-batch $? "not an interrupted batch"
"$SIM" $SCN --seeds 1..40 --quiet --out "$T/nothing" --resume 2>"$T/err"
one_line resume-nothing $? "not an interrupted batch"
interrupt INT "$T/cutx"
"$SIM" $SCN --seeds 1..41 --quiet --out "$T/cutx" --resume 2>"$T/err"
one_line resume-other-seeds $? "another batch"
check "resume-other-seeds-kept" '[ -e "$T/cutx/batch.state" ]'
exit $((fails > 0))
