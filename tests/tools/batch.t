#!/bin/sh
# tests/tools/batch.t - scripts/batch: its cache is keyed on the input and
# on the soupmesh options (all but --threads), not only on file times.
. "$(dirname "$0")/lib.sh"

B=$ROOT/scripts/batch
if ! command -v parallel >/dev/null 2>&1 && ! command -v xargs >/dev/null 2>&1; then
    echo "1..0 # SKIP neither GNU parallel nor xargs"
    exit 0
fi
cd "$WORK" || exit 1
mkdir -p in out
cat >in/cube.obj <<'OBJ'
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
OBJ
printf 'OFF\n4 4 0\n0 0 0\n2 0 0\n0 2 0\n0 0 2\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n' >in/tet.off
OPTS="--cells 3 --field-cells 16"

# batch_run NAME ARGS...: run the batch; its stderr and the table in .out.
batch_run() {
    "$B" --bin "$SOUPTET_BIN" -j 2 in out -- "$@" >"$WORK/table" 2>"$WORK/msg"
}

batch_run $OPTS
rc=$?
[ $rc -eq 0 ] && grep -q '2 models, 2 to mesh, 0 already done' msg &&
    [ "$(grep -c ' ok$' table)" -eq 2 ] && [ -s out/cube.key ] && [ -s out/tet.key ]
ok $? "the first run meshes both models and writes their keys"
[ $rc -eq 0 ] || sed 's/^/#   /' msg table | head -10

batch_run $OPTS
grep -q '2 models, 0 to mesh, 2 already done' msg && [ "$(grep -c ' cached$' table)" -eq 2 ]
ok $? "the same options again: both cached"

batch_run $OPTS --threads 2
grep -q '0 to mesh, 2 already done' msg
ok $? "another --threads (never changes a mesh): still cached"

cp out/cube.vtu cube-before.vtu
batch_run --cells 4 --field-cells 16
grep -q '2 models, 2 to mesh, 0 already done' msg && [ "$(grep -c ' ok$' table)" -eq 2 ]
ok $? "other options: both meshed again (the old code said cached)"
! cmp -s cube-before.vtu out/cube.vtu
ok $? "and the mesh is the new one"
grep -q '^option --cells$' out/cube.key && grep -q '^option 4$' out/cube.key &&
    grep -q '^input [0-9a-f]\{64\}$' out/cube.key
ok $? "the key lists the options and the input's SHA-256"

batch_run $OPTS
grep -q '2 to mesh' msg
ok $? "back to the first options: meshed again"

# The input's content is in the key (times alone can lie: cp -p, rsync -t).
sleep 1
printf 'OFF\n4 4 0\n0 0 0\n3 0 0\n0 3 0\n0 0 3\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n' >tet2.off
touch -d '2001-01-01' tet2.off && cp -p tet2.off in/tet.off
batch_run $OPTS
grep -q '2 models, 1 to mesh, 1 already done' msg
ok $? "an input replaced by an older file with other content: that one is meshed again"

# --one alone (a Slurm array task run twice) skips a model done with the
# same options and redoes one with others.
f=$WORK/in/cube.obj
before=$(stat -c %Y out/cube.vtu)
sleep 1
"$B" --one "$SOUPTET_BIN" "$f" "$WORK/out" vtu $OPTS 2>one.err
[ $? -eq 0 ] && [ "$(stat -c %Y out/cube.vtu)" = "$before" ]
ok $? "batch --one skips a model done with the same options"
"$B" --one "$SOUPTET_BIN" "$f" "$WORK/out" vtu --cells 4 --field-cells 16 2>one.err
[ $? -eq 0 ] && [ "$(stat -c %Y out/cube.vtu)" != "$before" ] && grep -q '^option 4$' out/cube.key
ok $? "batch --one redoes it with other options"

done_testing
