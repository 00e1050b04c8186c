#!/bin/sh
# tests/tools/docs.t - what the tools say matches what they do: the
# defaults and formats in --help and the man pages, the hints, the pipe of
# the README making soupmesh's mesh, -v reporting as a run goes, and a
# terminal on stdin refused like one on stdout.
. "$(dirname "$0")/lib.sh"
cd "$WORK" || exit 1

# soupsign's -k: the code's default is 1 (st_sign_params_default), 0.8 is
# the paper's rule.
soupsign --help | grep -q -- '-k K .*(default 1; paper: 0.8)'
ok $? "soupsign --help gives -k's default as 1 (the paper's 0.8 apart)"
sed -n '/^\.BI \\-k " K"/,/^\.TP/p' "$ROOT/man/man1/soupsign.1" | grep -q '(default 1;'
ok $? "soupsign(1) gives -k's default as 1"

tetstat --help | grep -q 'MESH is a tet mesh (.vtu .msh .mesh .node/.ele'
ok $? "tetstat --help names every mesh format it reads"
! soupmesh --help | grep -q 'holes\.h'
ok $? "soupmesh --help does not send users to a source header"
for t in soupdist soupinfo soupmesh tetstat tetsmooth; do
    $t --help | grep -q '\.gltf'
    ok $? "$t --help lists glTF among the surfaces"
done

expect_fail "soupwrap on a surface hints at --surface" 1 \
    "a surface\\? soupwrap --surface .*bunny\\.obj" soupwrap -o w.obj "$ROOT/corpus/bunny.obj"

# Every default --help and the man pages state, against the library's
# (test_defaults --print reads them from the code): one test per tool,
# option and text.
TB=${SOUPTET_TESTBIN:-$ROOT/build/tests}
"$TB/test_defaults" --print >defaults.txt
"$PYVTK" "$ROOT/tests/tools/defaults_check.py" defaults.txt "$ROOT/man/man1" >defaults.out 2>&1
while read -r res tool opt where rest; do
    [ "$res" = ok ]
    ok $? "$tool $opt: $where gives the code's default (${rest})"
done <defaults.out
[ "$(wc -l <defaults.out)" -ge 60 ]
ok $? "every default was compared ($(wc -l <defaults.out) lines)"

# The pipe of README and soupmesh(1) makes soupmesh's mesh exactly: the same
# points and tets bit for bit (only the metadata differ), at the defaults
# and with --cells, --seed and --offset carried over as the man page says.
cat >geomhash.py <<'EOF'
import sys, hashlib, meshio, numpy as np
for f in sys.argv[1:]:
    m = meshio.read(f)
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(m.points, dtype='<f8').tobytes())
    for c in m.cells:
        h.update(c.type.encode())
        h.update(np.ascontiguousarray(c.data, dtype='<i8').tobytes())
    print(h.hexdigest(), len(m.points), sum(len(c.data) for c in m.cells))
EOF
BUNNY="$ROOT/corpus/bunny.obj"
if "$PYVTK" -c 'import meshio' 2>/dev/null; then
    soupmesh -q -o one.vtu "$BUNNY"
    soupdist "$BUNNY" | soupsign | latticetet --sculpt --surface "$BUNNY" \
        | tetsmooth -q --fit --surface "$BUNNY" >pipe.vtu
    "$PYVTK" geomhash.py one.vtu >one.hash && "$PYVTK" geomhash.py pipe.vtu >pipe.hash &&
        cmp -s one.hash pipe.hash
    ok $? "the README's pipe makes soupmesh's mesh ($(cut -c1-12,65- one.hash) / $(cut -c1-12,65- pipe.hash))"
    soupmesh -q --cells 7 --seed 5 --offset 0.5 -o one7.vtu "$BUNNY"
    soupdist "$BUNNY" | soupsign | latticetet --sculpt --surface "$BUNNY" --cells 7 --seed 5 \
        | tetsmooth -q --fit --offset 0.5 --surface "$BUNNY" >pipe7.vtu
    "$PYVTK" geomhash.py one7.vtu >one7.hash && "$PYVTK" geomhash.py pipe7.vtu >pipe7.hash &&
        cmp -s one7.hash pipe7.hash
    ok $? "... and with --cells 7 --seed 5 --offset 0.5 ($(cut -c1-12,65- one7.hash) / $(cut -c1-12,65- pipe7.hash))"
else
    TAP_N=$((TAP_N + 1)); echo "ok $TAP_N - the pipe # SKIP meshio is missing"
    TAP_N=$((TAP_N + 1)); echo "ok $TAP_N - the pipe --cells 7 # SKIP meshio is missing"
fi

# -v reports as the run goes: every fit and quality iteration of every
# candidate and each candidate's end come before the final summary.
soupmesh -v --cells 5 --voxels 48 --tries 2 --threads 2 -o v.vtu "$BUNNY" 2>v.log
for k in 0 1; do
    grep -q "^soupmesh: candidate $k: [0-9]* tets sculpted" v.log &&
        grep -q "^soupmesh: candidate $k: fit   1: " v.log &&
        grep -q "^soupmesh: candidate $k: quality   1: " v.log &&
        grep -q "^soupmesh: candidate $k: done" v.log
    ok $? "soupmesh -v: candidate $k's sculpt, fit and quality iterations and end"
done
first_iter=$(grep -n ': fit   1: ' v.log | head -1 | cut -d: -f1)
summary=$(grep -n 'candidate 0 (seed' v.log | head -1 | cut -d: -f1)
[ -n "$first_iter" ] && [ -n "$summary" ] && [ "$first_iter" -lt "$summary" ]
ok $? "... before the summary (line ${first_iter:-none} < ${summary:-none})"
grep -q '^soupmesh: field [0-9]*x[0-9]*x[0-9]*, voxel .*: distance and signs' v.log
ok $? "... and the field as soon as it is done"
soupmesh -q --cells 5 --voxels 48 --tries 2 --threads 1 -o q.vtu "$BUNNY"
if "$PYVTK" -c 'import meshio' 2>/dev/null; then
    "$PYVTK" geomhash.py v.vtu >v.hash && "$PYVTK" geomhash.py q.vtu >q.hash && cmp -s v.hash q.hash
    ok $? "the reports change nothing: -v on 2 threads and -q on 1 give the same mesh"
fi

# A terminal on stdin: refused at once (exit 2), as a terminal on stdout
# is, instead of waiting silently. script(1) gives the tool a terminal.
if command -v script >/dev/null 2>&1; then
    soupmesh -q --cells 3 --voxels 32 -o small.vtu "$BUNNY"
    soupdist -r 32 -o small.vdb "$BUNNY"
    soupsign -o small-s.vdb small.vdb
    for cmd in "soupinfo" "tetstat" "soupdist -o x.vdb" "soupmesh -o x.vtu -" \
               "soupsign --surface - -o x.vdb small.vdb" \
               "latticetet --sculpt --surface - -o x.vtu small-s.vdb" \
               "tetsmooth --fit --surface - -o x.vtu small.vtu" \
               "soupwrap --surface - -o x.obj" "tetstat --surface - small.vtu"; do
        script -qec "$cmd" /dev/null </dev/null >tty.out 2>&1
        rc=$?
        [ $rc -eq 2 ] && grep -q 'will not read .*from a terminal' tty.out
        ok $? "$cmd with a terminal on stdin: refused, exit 2"
        [ $rc -eq 2 ] || sed 's/^/#   /' tty.out | head -3
    done
else
    TAP_N=$((TAP_N + 1)); echo "ok $TAP_N - terminal stdin # SKIP script(1) is not installed"
fi

done_testing
