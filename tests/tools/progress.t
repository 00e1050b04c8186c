#!/bin/sh
# tests/tools/progress.t - the progress line (issue 40, item 2), drawn on
# a stderr that is not a terminal with SOUPTET_PROGRESS=1: a stage's
# percentage never goes back, the clock moves while a stage reports
# nothing (no jump of more than 2 s), an ETA where the work is counted,
# the line cleared before the summary, and ended with a newline when a
# signal stops the tool.
. "$(dirname "$0")/lib.sh"
cd "$WORK" || exit 1
BUNNY="$ROOT/corpus/bunny.obj"

cat >lines.py <<'EOF'
import re, sys
# The records of a progress stream: split at \r, escape codes dropped.
data = open(sys.argv[1], 'rb').read().decode()
recs = [r.replace('\x1b[K', '') for r in data.split('\r')]
pat = re.compile(r'^(\w+): (.+?) +(\d+)% \((\d+) (?:s|min)(?:, ETA [^)]*)?\)$')
done = re.compile(r'^(\w+): (.+?) done; working \((\d+) s\)$')
bad, last, n, eta = [], None, 0, 0
for r in recs:
    m = pat.match(r)
    if not m:
        continue
    n += 1
    eta += 'ETA' in r
    stage, pct, sec = m.group(2), int(m.group(3)), int(m.group(4))
    if last and last[0] == stage:
        if pct < last[1] and last[1] - pct <= 50:
            bad.append('%s went back %d%% -> %d%%' % (stage, last[1], pct))
        if pct >= last[1] and sec - last[2] > 2:
            bad.append('%s: the clock jumped %d s -> %d s' % (stage, last[2], sec))
    last = (stage, pct, sec)
print('# %d records, %d with an ETA, %d "done; working"' % (n, eta, sum(bool(done.match(r)) for r in recs)))
for b in bad[:5]:
    print('#  ', b)
mode = sys.argv[2] if len(sys.argv) > 2 else 'monotone'
if mode == 'monotone':
    sys.exit(1 if bad or n < 3 else 0)
if mode == 'eta':
    sys.exit(0 if eta > 0 else 1)
EOF

# One batch of two candidates at 28 cells, one thread: about 3 s in the
# candidates' line on a quiet machine (at 20 cells it took 3 s once and,
# as the candidates got faster, under a second, too short for the ETA;
# at 12 cells each batch's line took about a second, and its ETA, shown
# past a second, came and went with the machine's load).
SOUPTET_PROGRESS=1 soupmesh --cells 28 --tries 2 --try-all --threads 1 -o m.vtu "$BUNNY" 2>p.err
ok $? "soupmesh with SOUPTET_PROGRESS=1 on a non-terminal"
"$PYVTK" lines.py p.err monotone
ok $? "every stage's percentage only goes up, its clock never jumps more than 2 s"
"$PYVTK" lines.py p.err eta >/dev/null
ok $? "a stage longer than a second shows an ETA"
"$PYVTK" -c '
import sys
d = open("p.err", "rb").read()
i = d.rfind(b"soupmesh: ")
sys.exit(0 if d[i - 4:i] == b"\r\x1b[K" and d[i:].count(b"\n") == 1 and b" tets, " in d[i:] else 1)'
ok $? "the summary line follows the progress line, cleared (\\r, erase-line)"
soupmesh -q --cells 4 -o q.vtu "$BUNNY" 2>q.err && ! [ -s q.err ]
ok $? "no line without SOUPTET_PROGRESS on a non-terminal (nor with -q)"
SOUPTET_PROGRESS=1 soupmesh -q --cells 4 -o q.vtu "$BUNNY" 2>q.err && ! [ -s q.err ]
ok $? "... and none with -q even when forced"

# Every stage moves (issue 40, item 2): on a holed soup whose run takes a
# few seconds (22 cells: each batch about a second on a quiet machine;
# at 12 and 16 cells a batch took under half a second and drew only
# 3-4 percentages), with two batches of candidates, the stages come in order,
# each batch of candidates shows distinct percentages as its candidates
# sculpt, fit and pass for quality (before,
# nothing moved between the distance band's 100% and the first
# candidate's end), and the line changes at least every 2.5 s.
cat >stamp.py <<'EOF'
import sys, time
# Each progress record of stdin, with the seconds since start.
t0, buf, out = time.time(), b'', open(sys.argv[1], 'w')
while True:
    c = sys.stdin.buffer.read(1)
    if not c:
        break
    if c in (b'\r', b'\n'):
        rec = buf.decode(errors='replace').replace('\x1b[K', '')
        if rec:
            out.write('%.3f %s\n' % (time.time() - t0, rec))
            out.flush()
        buf = b''
    else:
        buf += c
EOF
cat >stages.py <<'EOF'
import re, sys
pat = re.compile(r'^([\d.]+) soupmesh: (.+?) +(\d+)% \(')
recs = [(float(m.group(1)), m.group(2), int(m.group(3)))
        for m in map(pat.match, open(sys.argv[1])) if m]
order, pcts = [], {}
for t, stage, pct in recs:
    if not order or order[-1] != stage:
        order.append(stage)
    pcts.setdefault(stage, set()).add(pct)
gaps = [b[0] - a[0] for a, b in zip(recs, recs[1:])]
print('# stages: ' + ', '.join('%s (%d distinct)' % (s, len(pcts[s])) for s in order))
print('# longest time without a new record: %.2f s' % max(gaps or [0]))
# (a stage is drawn when 0.1 s passed since the last draw, or at its end:
# on a fast machine a short stage such as the sides may not show)
want = ['distance band', 'signs', 'candidates 1-2 of 4', 'candidates 3-4 of 4']
at = [order.index(w) if w in order else -1 for w in want]
bad = [w for w, i in zip(want, at) if i < 0]
if bad or at != sorted(at):
    print('# missing or out of order: %s' % bad)
    sys.exit(1)
if any(len(pcts[w]) < 3 for w in want[2:]):
    sys.exit(1)
sys.exit(0 if max(gaps or [0]) <= 2.5 else 1)
EOF
holed_bunny >holed.obj
(SOUPTET_PROGRESS=1 soupmesh --cells 22 --tries 4 --try-all -o h.vtu holed.obj 2>&1 >/dev/null;
 echo "exit $?" >&2) 2>h.rc | "$PYVTK" stamp.py h.rec
grep -q '^exit 0$' h.rc
ok $? "soupmesh on a holed soup, 4 candidates in 2 batches"
"$PYVTK" stages.py h.rec
ok $? "each stage in order; each batch of candidates moves (>= 3 distinct percentages: before, its 'candidates N%' went from 0 to 100 in one step), a new record at least every 2.5 s"

# A signal mid-run: the line ends with a newline (the shell's prompt
# starts a line of its own), and no output is left.
for sig in INT TERM; do
    SOUPTET_PROGRESS=1 soupmesh --cells 30 --tries 4 -o s.vtu "$BUNNY" 2>s.err &
    pid=$!
    i=0
    while [ $i -lt 50 ] && ! grep -q '%' s.err 2>/dev/null; do sleep 0.1; i=$((i + 1)); done
    sleep 0.5
    kill -$sig $pid
    wait $pid
    rc=$?
    last=$(tail -c 1 s.err | od -An -c | tr -d ' ')
    [ $rc -gt 128 ] && grep -q '%' s.err && [ "$last" = '\n' ] && ! [ -e s.vtu ]
    ok $? "SIG$sig during the run: the progress line ends with a newline (exit $rc, last byte '$last')"
done

done_testing
