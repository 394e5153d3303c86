#!/bin/sh
# Power loss, as SIGKILL: a simulated scan killed at KILLS random moments (default 50), resumed
# with `scanner resume` after each, the resume itself killed in turn. After every kill each view
# whose view.ini is on disk must hold exactly the frames of an uninterrupted scan (nothing torn,
# nothing lost), and every scan that gets to its end must give the uninterrupted scan's model,
# byte for byte. Prints cmocka-style lines for tests/run.sh.
set -u
cd "$(dirname "$0")/.."
bin=${BUILD:-build}/scanner
out=${BUILD:-build}/resume
kills=${KILLS:-50}
seed=${SEED:-7}
rm -rf "$out"
mkdir -p "$out"
fail() {
    echo "[  FAILED  ] $1"
    echo "[  FAILED  ] 1 test(s)."
    exit 1
}
"$bin" scan --config tests/resume.ini --out "$out/reference" >"$out/reference.log" 2>&1 ||
    fail "reference scan: $(tail -n 1 "$out/reference.log")"
# Delays in ms, uniform in 100..2500, from a seeded generator so a failure can be replayed.
awk -v n="$kills" -v s="$seed" 'BEGIN { srand(s); for (i = 0; i < n; i++) print int(100 + rand() * 2400) }' \
    >"$out/delays"
intact() { # every finished view holds the reference's frames
    for ini in "$out/killed"/view_*/view.ini; do
        [ -f "$ini" ] || continue
        v=$(dirname "$ini")
        for f in "$out/reference/$(basename "$v")"/frame_*.png; do
            cmp -s "$f" "$v/$(basename "$f")" || return 1
        done
    done
}
done_kills=0
finished=0
cmd="scan --config tests/resume.ini --out $out/killed"
while read -r ms; do
    "$bin" $cmd >>"$out/run.log" 2>&1 &
    pid=$!
    sleep "$(awk -v ms="$ms" 'BEGIN { printf "%.3f", ms / 1000 }')"
    if kill -KILL "$pid" 2>/dev/null; then
        wait "$pid" 2>/dev/null
        done_kills=$((done_kills + 1))
        intact || fail "kill $done_kills after $ms ms: a finished view's frames differ from the reference"
        cmd="resume $out/killed"
        # killed before the scan had written anything: there is nothing to resume; start again
        [ -f "$out/killed/config.ini" ] || cmd="scan --config tests/resume.ini --out $out/killed --replace"
        continue
    fi
    wait "$pid" || fail "'scanner $cmd' failed: $(tail -n 3 "$out/run.log")"
    cmp -s "$out/killed/mesh.ply" "$out/reference/mesh.ply" ||
        fail "the model after $done_kills kills differs from the uninterrupted scan's"
    finished=$((finished + 1))
    rm -rf "$out/killed" # and a new scan, to be killed again
    cmd="scan --config tests/resume.ini --out $out/killed"
done <"$out/delays"
if [ -d "$out/killed" ]; then # the last interrupted scan, resumed to its end
    "$bin" resume "$out/killed" >>"$out/run.log" 2>&1 || fail "last resume: $(tail -n 3 "$out/run.log")"
    cmp -s "$out/killed/mesh.ply" "$out/reference/mesh.ply" ||
        fail "the model after $done_kills kills differs from the uninterrupted scan's"
    finished=$((finished + 1))
fi
echo "[       OK ] sigkill_and_resume: $done_kills kills, $finished scans finished, each model identical"
# A two-pass scan killed in its second pass: resume asks for the object laid as the second pass
# wants (the simulated person lays it), takes the rest and gives the uninterrupted model.
two=tests/resume-two-pass.ini
"$bin" scan --config $two --out "$out/two-reference" >"$out/two-reference.log" 2>&1 ||
    fail "two-pass reference scan: $(tail -n 1 "$out/two-reference.log")"
"$bin" scan --config $two --out "$out/two" >"$out/two.log" 2>&1 &
pid=$!
while kill -0 "$pid" 2>/dev/null && [ ! -f "$out/two/view_005/view.ini" ]; do sleep 0.2; done
kill -KILL "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
[ -f "$out/two/view_005/view.ini" ] && [ ! -f "$out/two/mesh.ply" ] ||
    fail "the two-pass scan was not stopped in its second pass"
"$bin" resume "$out/two" --config $two >>"$out/two.log" 2>&1 || fail "two-pass resume: $(tail -n 3 "$out/two.log")"
grep -q '>>> pass 2 of 2' "$out/two.log" || fail "resume in the second pass did not ask for the object"
cmp -s "$out/two/mesh.ply" "$out/two-reference/mesh.ply" ||
    fail "the two-pass model after a kill in its second pass differs from the uninterrupted one"
echo "[       OK ] two_pass_killed_in_second_pass_resumes"
echo "[  PASSED  ] 2 test(s)."
