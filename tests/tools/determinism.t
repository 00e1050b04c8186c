#!/bin/sh
# determinism: every tool's output depends only on its inputs and seed, not
# on the thread count, the run, or the load on the machine (issue #8,
# item 6). Each case runs the same command line (the output's history
# records it) with 1, 2 and 3 OpenMP threads, 3 twice, two runs at a time
# (so they compete for the cores of a 2-core machine); every output file
# must be byte-identical across the four. OpenVDB writes a random UUID into
# every .vdb file and stream: it is blanked before comparing (the only
# bytes that may differ).
. "$(dirname "$0")/lib.sh"
BUNNY="$ROOT/corpus/bunny.obj"
cd "$WORK" || exit 1

cat > unuuid.py <<'PY'
import re, sys
d = open(sys.argv[1], "rb").read()
d, n = re.subn(rb"[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}", b"0" * 36, d, count=1)
assert n == 1, "no UUID in " + sys.argv[1]
open(sys.argv[2], "wb").write(d)
PY

# same_file A B: identical bytes (for .vdb: but for the UUID).
same_file() {
    case $1 in
    *.vdb)
        /usr/bin/python3 unuuid.py "$1" "$1.u" && /usr/bin/python3 unuuid.py "$2" "$2.u" &&
            cmp -s "$1.u" "$2.u" ;;
    *) cmp -s "$1" "$2" ;;
    esac
}

# same NAME "FILES" CMD: CMD (a shell command run in each folder) in r1 and
# r2 with 1 and 2 threads side by side, then in r3 and r3b with 3 threads
# side by side; each FILE must be non-empty and the same in all four.
same() {
    name=$1 files=$2 cmd=$3
    for d in r1 r2 r3 r3b; do
        rm -rf $d
        mkdir $d
    done
    rc=0
    (cd r1 && OMP_NUM_THREADS=1 sh -c "$cmd") 2>r1.err &
    pid=$!
    (cd r2 && OMP_NUM_THREADS=2 sh -c "$cmd") 2>r2.err || rc=1
    wait $pid || rc=1
    (cd r3 && OMP_NUM_THREADS=3 sh -c "$cmd") 2>r3.err &
    pid=$!
    (cd r3b && OMP_NUM_THREADS=3 sh -c "$cmd") 2>r3b.err || rc=1
    wait $pid || rc=1
    why=
    for f in $files; do
        test -s "r1/$f" || why="$why r1/$f:empty"
        for d in r2 r3 r3b; do
            same_file "r1/$f" "$d/$f" || why="$why $d/$f"
        done
    done
    [ $rc -eq 0 ] && [ -z "$why" ]
    ok $? "$name"
    [ $rc -eq 0 ] || sed 's/^/#   /' r1.err r2.err r3.err r3b.err | head -5
    [ -z "$why" ] || echo "#   differs:$why"
}

soupdist -q -r 32 -o d.vdb "$BUNNY"
soupsign -q -o s.vdb d.vdb
latticetet -q --density 0.5 --cells 8 -o l.vtu s.vdb
latticetet -q --sculpt --surface "$BUNNY" --cells 6 -o b6.vtu s.vdb
# The fit and quality loops run a colour set in parallel only past 64
# vertices (PAR_CHECKED, src/tet/smooth_mesh.h): b6's largest has 48, so
# with it those loops always ran on one thread; b12's largest has 182.
latticetet -q --sculpt --surface "$BUNNY" --cells 12 -o b12.vtu s.vdb
# The bunny as an exact soup (every triangle its own vertices).
awk '/^v /{v[++n]=$0} /^f /{split($2,a,"/");split($3,b,"/");split($4,c,"/");
     print v[a[1]]; print v[b[1]]; print v[c[1]]; m+=3; f[++k]="f " m-2 " " m-1 " " m}
     END{for(i=1;i<=k;i++) print f[i]}' "$BUNNY" > soup.obj
check "the inputs are made" test -s d.vdb -a -s s.vdb -a -s l.vtu -a -s b6.vtu -a -s b12.vtu \
    -a -s soup.obj

# The control: the comparison sees a difference where there is one.
mkdir c1 c2
(cd c1 && soupdist -q -r 24 -o f.vti "$BUNNY")
(cd c2 && soupdist -q -r 25 -o f.vti "$BUNNY")
! same_file c1/f.vti c2/f.vti
ok $? "control: -r 24 and -r 25 give different files"
(cd c1 && soupdist -q -r 24 -o f.vdb "$BUNNY")
(cd c2 && soupdist -q -r 24 -o f.vdb "$BUNNY")
! cmp -s c1/f.vdb c2/f.vdb && same_file c1/f.vdb c2/f.vdb
ok $? "control: two .vdb files of one field differ in their UUID only"

same "soupdist -> .vti, .vdb and a VDB stream on stdout" "f.vti f.vdb g.vdb" \
    "soupdist -q -r 48 -o f.vti '$BUNNY' && soupdist -q -r 40 -o f.vdb '$BUNNY' &&
     soupdist -q -r 32 '$BUNNY' > g.vdb"
same "soupdist --band full (propagated beyond the band)" "f.vti" \
    "soupdist -q --band full -r 20 -o f.vti '$BUNNY'"
same "soupsign: the default rule and --rule paper --rays 13" "s.vti p.vti" \
    "soupsign -q -o s.vti ../d.vdb && soupsign -q --rule paper --rays 13 -o p.vti ../d.vdb"
same "soupwrap -> .obj" "w.obj" "soupwrap -q -o w.obj ../s.vdb"
same "soupwrap --surface --smooth --adaptivity -> .ply" "w.ply" \
    "soupwrap -q --surface '$BUNNY' -r 24 --smooth 2 --adaptivity 0.3 -o w.ply"
same "latticetet --density, bcc, seeded -> .msh" "t.msh" \
    "latticetet -q --density 0.5 --lattice bcc --cells 10 --seed 2 -o t.msh ../s.vdb"
same "tetsmooth --fair" "f.vtu" "tetsmooth -q --fair -o f.vtu ../l.vtu"
same "tetsmooth --fit (with the quality pass)" "f.vtu" \
    "tetsmooth -q --fit --surface '$BUNNY' -o f.vtu ../b6.vtu"
same "tetsmooth --fit on 12 cells (colour sets large enough to run in parallel)" "f.vtu" \
    "tetsmooth -q --fit --surface '$BUNNY' -o f.vtu ../b12.vtu"
same "tetstat --json --surface --field" "r.json" \
    "tetstat -q --json --surface '$BUNNY' --field ../s.vdb ../l.vtu > r.json"
same "soupinfo --json (with the self-intersection test)" "r.json" \
    "soupinfo --json '$BUNNY' ../soup.obj > r.json"
same "soupmesh, 3 candidates -> .node/.ele with --embed" "m.node m.ele e.txt" \
    "soupmesh -q --offset-best-effort --cells 4 --voxels 32 --tries 3 --embed e.txt -o m.node '$BUNNY'"

# --tries 1: one candidate gets every thread (with more, each candidate
# runs on one), at 12 cells its fit and quality loops run in parallel.
same "soupmesh, 1 candidate at 12 cells -> .vtu" "m.vtu" \
    "soupmesh -q --offset-best-effort --cells 12 --voxels 32 --tries 1 -o m.vtu '$BUNNY'"

# tetstat's report holds no command line: there --threads itself can vary.
for n in 1 2 3; do
    tetstat -q --threads $n --json --surface "$BUNNY" b6.vtu > th$n.json
done
cmp -s th1.json th2.json && cmp -s th1.json th3.json && test -s th1.json
ok $? "tetstat --threads 1, 2, 3: the same report"

done_testing
