#!/bin/sh
# soupinfo end to end: the bundled bunny, an exact soup, JSON that parses,
# several inputs, stdin, bad input, usage errors.
. "$(dirname "$0")/lib.sh"
BUNNY="$ROOT/corpus/bunny.obj"
cd "$WORK" || exit 1

check "--help exits 0" sh -c 'soupinfo --help | grep -q "Usage: soupinfo"'
check "--version names the project" sh -c 'soupinfo --version | grep -q "(souptet)"'
check "man page exists and renders" sh -c "man -l '$ROOT/man/man1/soupinfo.1' >/dev/null 2>&1 || test -s '$ROOT/man/man1/soupinfo.1'"

# The bunny: closed, one piece, no boundary edges, genus 0.
check "bunny: table" sh -c "soupinfo '$BUNNY' > bunny.txt"
check "bunny: closed" grep -Eq '^  closed +yes$' bunny.txt
check "bunny: 1 piece" grep -Eq '^  pieces +1$' bunny.txt
check "bunny: 0 boundary edges" grep -Eq '^    boundary +0$' bunny.txt
check "bunny: JSON parses (python3 -m json.tool)" sh -c "soupinfo --json '$BUNNY' > bunny.json && python3 -m json.tool bunny.json > /dev/null"
cat > want.py <<'PY'
import json, sys
# want.py FILE KEY=VALUE...: the first report in FILE has these values
r = json.load(open(sys.argv[1]))[0]
for kv in sys.argv[2:]:
    k, v = kv.split("=")
    got = r[k]
    want = {"true": True, "false": False}.get(v, v)
    if isinstance(got, bool) or not isinstance(got, int):
        ok = got == want
    else:
        ok = got == int(want)
    if not ok:
        sys.exit("%s: %s is %r, wanted %s" % (sys.argv[1], k, got, v))
PY
check "bunny: JSON counts" python3 want.py bunny.json vertices=1839 triangles=3674 \
    closed=true pieces=1 boundary_edges=0 holes=0 genus=0 euler=2 \
    consistently_oriented=true degenerate_triangles=0 duplicated_triangles=0

# The same bunny as an exact soup (every triangle its own vertices, written
# with the same digits): welds back to one closed piece.
awk '/^v /{v[++n]=$0} /^f /{split($2,a,"/");split($3,b,"/");split($4,c,"/");
     print v[a[1]]; print v[b[1]]; print v[c[1]]; m+=3; f[++k]="f " m-2 " " m-1 " " m}
     END{for(i=1;i<=k;i++) print f[i]}' "$BUNNY" > soup.obj
check "exact soup: 3 x 3674 vertices, welds to 1839 points, one closed piece" \
    sh -c "soupinfo --json soup.obj > soup.json && python3 want.py soup.json vertices=11022 welded_vertices=1839 pieces=1 closed=true"

# Several inputs: one JSON array in order; stdin.
check "two inputs: a JSON array of two" sh -c "soupinfo --json '$BUNNY' soup.obj | python3 -c 'import json,sys; d=json.load(sys.stdin); assert [r[\"vertices\"] for r in d] == [1839, 11022]'"
check "stdin" sh -c "soupinfo --json - < '$BUNNY' | python3 -c 'import json,sys; assert json.load(sys.stdin)[0][\"file\"] == \"<stdin>\"'"
check "no input means stdin" sh -c "soupinfo < '$BUNNY' | grep -q '^<stdin>:'"

# A cube missing one face: 4 boundary edges, one hole.
cat > open.off <<'END'
OFF
8 10 0
0 0 0
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
3 4 5 6
3 4 6 7
3 0 1 5
3 0 5 4
3 2 3 7
3 2 7 6
3 0 4 7
3 0 7 3
3 1 2 6
3 1 6 5
END
check "open cube: 4 boundary edges, 1 hole, not closed" sh -c "soupinfo --json open.off > open.json && python3 want.py open.json boundary_edges=4 holes=1 closed=false euler=1"

# Bad input: exit 1, "soupinfo: FILE:LINE: what"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n' > range.obj
expect_fail "index out of range: file and line" 1 "^soupinfo: range.obj:4: " soupinfo range.obj
printf 'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 nan\n3 0 1 2\n' > nan.off
expect_fail "NaN coordinate: file and line" 1 "^soupinfo: nan.off:5: " soupinfo nan.off
: > empty.stl
expect_fail "empty file" 1 "^soupinfo: empty.stl" soupinfo empty.stl
expect_fail "a missing file" 1 "^soupinfo: missing.obj" soupinfo missing.obj
check "a bad input among good ones: the others are reported, exit 1" sh -c "
    soupinfo --json '$BUNNY' range.obj soup.obj > mixed.json 2> mixed.err; rc=\$?
    test \$rc -eq 1 && grep -q '^soupinfo: range.obj:4: ' mixed.err &&
    python3 -c 'import json; assert len(json.load(open(\"mixed.json\"))) == 2'"

# Usage errors: exit 2
expect_fail "unknown option" 2 "unknown option" soupinfo --bogus "$BUNNY"
expect_fail "stdin twice" 2 "standard input" soupinfo - -

# Self-intersections (exact): none on the bunny; two overlapping cubes cross.
check "bunny: no self-intersecting pairs" python3 want.py bunny.json self_intersecting_pairs=0 collinear_triangles=0
awk 'BEGIN{print "OFF"; print "16 24 0";
  for(c=0;c<2;c++) for(i=0;i<8;i++) print (i%2)+c*0.5, (int(i/2)%2)+c*0.5, int(i/4)+c*0.5;
  split("0 2 1 1 2 3 4 5 6 5 7 6 0 1 4 1 5 4 2 6 3 3 6 7 0 4 2 2 4 6 1 3 5 3 7 5", f, " ");
  for(c=0;c<2;c++) for(t=0;t<12;t++) print 3, f[3*t+1]+8*c, f[3*t+2]+8*c, f[3*t+3]+8*c}' > overlap.off
check "two overlapping cubes: self-intersecting pairs found" sh -c \
    "soupinfo --json overlap.off > o.json && python3 -c 'import json; r=json.load(open(\"o.json\"))[0]; assert r[\"self_intersecting_pairs\"] > 0 and r[\"closed\"], r'"
check "--no-self-check: the keys are null" sh -c \
    "soupinfo --json --no-self-check overlap.off | python3 -c 'import json,sys; assert json.load(sys.stdin)[0][\"self_intersecting_pairs\"] is None'"
check "table: the self-intersecting row" sh -c "soupinfo overlap.off | grep -Eq '^  self-intersecting pairs +[1-9]'"

done_testing
