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
OPTS="--cells 3 --voxels 16"

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
batch_run --cells 4 --voxels 16
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
"$B" --one "$SOUPTET_BIN" "$f" "$WORK/out" vtu --cells 4 --voxels 16 2>one.err
[ $? -eq 0 ] && [ "$(stat -c %Y out/cube.vtu)" != "$before" ] && grep -q '^option 4$' out/cube.key
ok $? "batch --one redoes it with other options"

# ---- a job killed by SIGKILL -----------------------------------------------
# soupmesh on one model dies by SIGKILL (no handler sees it) with its mesh
# written to the temporary and not yet renamed: a preloaded rename() raises
# SIGKILL for that target. The batch (-j 2, three models) then leaves only
# that temporary, named for the target and the dead pid; a rerun removes
# it (the pid is gone) and completes. The old temporary name held no pid,
# so nothing could tell it was stale and it stayed.
cat >killrename.c <<'EOF2'
#define _GNU_SOURCE
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
int rename(const char *from, const char *to)
{
    const char *victim = getenv("KILL_AT_RENAME");
    if (victim && strstr(to, victim))
        raise(SIGKILL);
    return renameat(AT_FDCWD, from, AT_FDCWD, to);
}
EOF2
if cc -shared -fPIC -o killrename.so killrename.c 2>cc.err; then
    mkdir -p kin kout kbin
    cp in/cube.obj in/tet.off kin/
    printf 'OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n' >kin/victim.off
    ln -s "$SOUPTET_BIN/tetstat" kbin/tetstat
    # (ASan insists on coming first among the preloaded libraries.)
    cat >kbin/soupmesh <<EOF2
#!/bin/sh
ASAN_OPTIONS=\${ASAN_OPTIONS:+\$ASAN_OPTIONS:}verify_asan_link_order=0 \\
    LD_PRELOAD=$WORK/killrename.so KILL_AT_RENAME=victim.vtu exec "$SOUPTET_BIN/soupmesh" "\$@"
EOF2
    chmod +x kbin/soupmesh
    "$B" --bin kbin -j 2 kin kout -- $OPTS >ktable 2>kmsg
    rc=$?
    [ $rc -eq 1 ] && grep -q '^victim .*FAILED' ktable && [ "$(grep -c ' ok$' ktable)" -eq 2 ] &&
        grep -q 'soupmesh failed' kout/victim.log
    ok $? "soupmesh killed by SIGKILL on one model: that model failed, the two others meshed"
    grep -Eq '^2 meshed, 0 cached, 1 failed, in [0-9.]+ s' kmsg
    ok $? "the closing count says 2 meshed and 1 failed (it said 3 models meshed)"
    [ ! -e kout/joblog ]
    ok $? "no undocumented joblog in the output folder"
    [ $rc -eq 1 ] || { echo "#   exit $rc"; sed 's/^/#   /' kmsg ktable | head; }
    left=$(cd kout && ls -A | grep '^\.')
    n=$(printf '%s\n' "$left" | grep -c .)
    pat="^\.victim\.vtu\.tmp-[0-9]+@$(hostname | tr './@' '___')\.[A-Za-z0-9]{6}\$"
    [ "$n" -eq 1 ] && printf '%s\n' "$left" | grep -Eq "$pat" &&
        [ ! -e kout/victim.vtu ] && [ ! -e kout/victim.json ] && [ ! -e kout/victim.key ]
    ok $? "what is left is the one temporary, named for its target, pid and host: $left"
    pid=$(printf '%s\n' "$left" | sed 's/.*\.tmp-\([0-9]*\)@.*/\1/')
    [ -n "$pid" ] && [ ! -d "/proc/$pid" ]
    ok $? "its pid ($pid) is gone"
    # A live process's temporary (this shell's) and one of another machine
    # stay; a dead process's beside a model that is not redone goes.
    live=".cube.vtu.tmp-$$@$(hostname | tr './@' '___').AbC123"
    other=".tet.vtu.tmp-$pid@not-$(hostname | tr './@' '___').AbC123"
    dead=".tet.json.tmp-$pid@$(hostname | tr './@' '___').AbC123"
    : >"kout/$live"; : >"kout/$other"; : >"kout/$dead"
    rm kbin/soupmesh && ln -s "$SOUPTET_BIN/soupmesh" kbin/soupmesh
    "$B" --bin kbin -j 2 kin kout -- $OPTS >ktable 2>kmsg
    rc=$?
    [ $rc -eq 0 ] && grep -q '3 models, 1 to mesh, 2 already done' kmsg &&
        grep -q '^victim .* ok$' ktable && [ -s kout/victim.vtu ] && [ -s kout/victim.json ]
    ok $? "the rerun completes the corpus (victim meshed, the others cached)"
    [ $rc -eq 0 ] || { echo "#   exit $rc"; sed 's/^/#   /' kmsg ktable | head; }
    grep -q "removed .*/$(printf '%s' "$left" | sed 's/\./\\./g'), left by process $pid (gone)" kmsg &&
        [ ! -e "kout/$left" ] && [ ! -e "kout/$dead" ]
    ok $? "and removes the dead process's temporaries, saying so"
    [ "$(cd kout && ls -A | grep '^\.' | sort | tr '\n' ' ')" = "$(printf '%s\n' "$live" "$other" | sort | tr '\n' ' ')" ]
    ok $? "a live process's temporary and another machine's stay, nothing else is left"
else
    sed 's/^/#   /' cc.err
    ok 1 "a C compiler for the SIGKILL test's preloaded rename()"
fi

# The report and the key get the mesh's mode (mktemp's 0600 was kept).
[ "$(stat -c %a out/cube.json)" = "$(stat -c %a out/cube.vtu)" ] &&
    [ "$(stat -c %a out/cube.key)" = "$(stat -c %a out/cube.vtu)" ]
ok $? "the .json and .key have the mesh's mode ($(stat -c %a out/cube.json), $(stat -c %a out/cube.vtu))"

done_testing
