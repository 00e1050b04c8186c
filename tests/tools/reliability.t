#!/bin/sh
# reliability: a run cut short or an output that cannot be written leaves
# no partial file and a non-zero exit (signals, a closed pipe, write errors,
# a full disk), and the memory limits refuse a job before anything large is
# allocated (issue #8, items 3 and 4).
. "$(dirname "$0")/lib.sh"
BUNNY="$ROOT/corpus/bunny.obj"
cd "$WORK" || exit 1

skip() {
    TAP_N=$((TAP_N + 1))
    echo "ok $TAP_N - $1 # SKIP $2"
}

# st_outfile's temporaries are "dir/.NAME.tmp-PID@HOST.XXXXXX" (src/base/outfile.c).
no_temps() {
    ! ls -A "$1" | grep -Eq '^\..+\.[A-Za-z0-9]{6}$'
}

soupdist -q -r 48 -o d.vdb "$BUNNY"
soupsign -q -o s.vdb d.vdb
latticetet -q --density 0.5 --cells 8 -o l.vtu s.vdb
soupdist -q -r 64 -o d64.vdb "$BUNNY"
soupsign -q -o s64.vdb d64.vdb
latticetet -q --density 0.5 --cells 30 -o l30.vtu s64.vdb
check "the inputs are made" test -s d.vdb -a -s s.vdb -a -s l.vtu -a -s l30.vtu

# ---- signals -----------------------------------------------------------
# interrupt SIG DIR: soupdist -r 320 into DIR/big.vti in the background
# (about 0.5 s of distances, then about 0.5 s writing); once its temporary
# DIR/.big.vti.tmp-PID@HOST.XXXXXX exists (the write has begun), send SIG. The tool's
# exit status is left in $irc ("none" when the temporary never appeared).
interrupt() {
    soupdist -q -r 320 -o "$2/big.vti" "$BUNNY" &
    pid=$!
    n=0
    seen=0
    while [ $n -lt 3000 ]; do
        for f in "$2"/.big.vti.*; do
            [ -e "$f" ] && seen=1
        done
        [ $seen -eq 1 ] && break
        kill -0 $pid 2>/dev/null || break
        sleep 0.01
        n=$((n + 1))
    done
    [ $seen -eq 1 ] && kill -s "$1" $pid
    wait $pid 2>/dev/null
    irc=$?
    [ $seen -eq 1 ] || irc=none
}

# whole_or_none DIR: DIR/big.vti does not exist, or (the signal came
# after the rename, which the polling cannot rule out) it is the whole
# field; said when so, since then the unlink was not exercised.
whole_or_none() {
    test ! -e "$1/big.vti" && return 0
    echo "#   (the signal arrived after the rename: $1/big.vti is complete?)"
    soupsign -q "$1/big.vti" > /dev/null 2>&1
}

# Under load the tool may finish between the poll that saw its temporary
# and the kill: then it exits 0 with the whole field, which is as correct
# as dying by the signal with no output. sig_ok SIG CODE DIR: either.
sig_ok() {
    if [ "$irc" = "$2" ]; then
        return 0
    elif [ "$irc" = 0 ] && soupsign -q "$3/big.vti" > /dev/null 2>&1; then
        echo "#   (SIG$1 came after the tool finished: exit 0, $3/big.vti complete)"
        return 0
    fi
    echo "#   exit $irc"
    return 1
}

mkdir int term over
interrupt INT int
sig_ok INT 130 int
ok $? "SIGINT while writing: the tool dies by SIGINT (exit 130), or had finished"
whole_or_none int
ok $? "SIGINT: no output file (or the whole one)"
no_temps int
ok $? "SIGINT: the temporary file is removed"

interrupt TERM term
sig_ok TERM 143 term
ok $? "SIGTERM while writing: the tool dies by SIGTERM (exit 143), or had finished"
whole_or_none term
ok $? "SIGTERM: no output file (or the whole one)"
no_temps term
ok $? "SIGTERM: the temporary file is removed"

printf 'the previous result\n' > over/big.vti
cp over/big.vti before.vti
interrupt TERM over
sig_ok TERM 143 over
ok $? "SIGTERM while overwriting: exit 143, or had finished"
# (killed just after the rename, or finished: the whole new field)
cmp -s before.vti over/big.vti || soupsign -q over/big.vti > /dev/null 2>&1
ok $? "SIGTERM while overwriting: the old file is left as it was (or the whole new one)"
no_temps over
ok $? "SIGTERM while overwriting: the temporary file is removed"

# ---- a closed pipe -----------------------------------------------------
# piped CMD...: CMD's output into head -c 100, which exits at once; CMD's
# exit status in $prc (124: it hung for 60 s). Every output here is well
# over a pipe's 64 KiB, so the tool is still writing when head leaves.
piped() {
    { timeout 60 "$@" 2>/dev/null; echo $? > prc.txt; } | head -c 100 > /dev/null
    prc=$(cat prc.txt)
}
for cmd in "soupdist -r 128 $BUNNY" "soupsign d64.vdb" "soupwrap s.vdb" \
           "latticetet --density 0.5 --cells 30 s64.vdb" \
           "tetsmooth --fair --iters 1 --no-quality l30.vtu" \
           "soupmesh -q --offset-best-effort --cells 10 --voxels 32 --max-iters 5 --no-quality $BUNNY"; do
    tool=${cmd%% *}
    # shellcheck disable=SC2086
    piped $cmd
    [ "$prc" -ne 0 ] && [ "$prc" -ne 124 ]
    ok $? "$tool | head -c 100: the tool stops with a non-zero status (got $prc), no hang"
done
no_temps .
ok $? "closed pipes: no temporary files"

# ---- write errors ------------------------------------------------------
for cmd in "soupdist -r 32 $BUNNY" "soupsign d.vdb" "soupwrap s.vdb" \
           "latticetet --density 0.5 --cells 8 s.vdb" "tetsmooth --fair l.vtu" \
           "tetstat l.vtu" "tetstat --json l.vtu" "soupinfo $BUNNY" \
           "soupmesh -q --offset-best-effort --cells 4 --voxels 32 $BUNNY"; do
    tool=${cmd%% *}
    expect_fail "$cmd > /dev/full: exit 1, '<stdout>: write failed'" 1 \
        "^$tool: <stdout>: write (failed|error)" sh -c "$cmd > /dev/full"
done
expect_fail "--help > /dev/full: exit 1" 1 "^soupdist: <stdout>: write failed: No space" \
    sh -c "soupdist --help > /dev/full"
expect_fail "--version > /dev/full: exit 1" 1 "^tetstat: <stdout>: write failed" \
    sh -c "tetstat --version > /dev/full"
expect_fail "stdout closed: exit 1, not a silent loss" 1 "^soupdist: <stdout>: write failed" \
    sh -c "soupdist -r 16 '$BUNNY' >&-"
expect_fail "a report with stdout closed: exit 1" 1 "^tetstat: <stdout>: write failed" \
    sh -c "tetstat l.vtu >&-"
check "stdout closed and -o FILE: the file is written whole (nothing lands in it from stdout)" \
    sh -c "soupdist -q -r 16 -o closed.vdb '$BUNNY' >&- && soupsign -q -o closed-s.vdb closed.vdb"

# A target that is not a regular file: renaming over it would replace the
# device itself.
ln -s /dev/full full.vdb
expect_fail "-o a symlink to /dev/full: refused before the work" 1 \
    "^soupdist: full.vdb: not a regular file" soupdist -r 16 -o full.vdb "$BUNNY"
test -c /dev/full && test -L full.vdb
ok $? "/dev/full is still a device, the link still a link"
mkdir adir.vtu
expect_fail "-o a directory: refused" 1 "^latticetet: adir.vtu: is a directory" \
    latticetet --density 0.5 --cells 8 -o adir.vtu s.vdb

# A full disk: a 64 KiB tmpfs, every writer with more than that to write.
mkdir full
if mount -t tmpfs -o size=64k tmpfs full 2>/dev/null; then
    trap 'umount "$WORK/full" 2>/dev/null; rm -rf "$WORK"' EXIT
    # one of each way of writing: VTK by name (.vti, .vtu), OpenVDB's
    # stream (.vdb), stdio streams (soupwrite.c .obj .stl, tetformat.c
    # .msh, the .node/.ele pair)
    for c in "soupdist -r 64 -o full/x.vti $BUNNY" "soupdist -r 64 -o full/x.vdb $BUNNY" \
             "soupwrap -o full/x.obj s.vdb" "soupwrap -o full/x.stl s.vdb" \
             "latticetet --density 0.5 --cells 30 -o full/x.vtu s64.vdb" \
             "latticetet --density 0.5 --cells 30 -o full/x.msh s64.vdb" \
             "soupmesh -q --offset-best-effort --cells 8 --voxels 32 --max-iters 5 --no-quality -o full/x.node $BUNNY"; do
        tool=${c%% -*}
        out=$(echo "$c" | sed 's/.*-o \(full\/[^ ]*\).*/\1/')
        # (a TetGen pair may fail on either file)
        expect_fail "full disk: $tool -o ${out#full/}: exit 1 naming it" 1 "^$tool: full/x\.[a-z]+: " $c
        [ -z "$(ls -A full)" ]
        ok $? "full disk: $tool -o ${out#full/}: nothing left on the disk"
        rm -rf full/* full/.[!.]* 2>/dev/null
    done
    expect_fail "full disk: soupmesh --embed full/e.txt: exit 1 naming it" 1 "^soupmesh: full/e.txt: " \
        soupmesh -q --cells 4 --voxels 32 --embed full/e.txt -o m4.vtu "$BUNNY"
    [ -z "$(ls -A full)" ]
    ok $? "full disk: soupmesh --embed full/e.txt: nothing left on the disk"
    umount full
else
    skip "a full disk" "cannot mount a tmpfs here"
fi

# A file size limit (ulimit -f): the write fails with EFBIG (SIGXFSZ is
# ignored), is reported, and the temporary is removed.
mkdir fsz
for c in "soupdist -r 64 -o fsz/x.vti $BUNNY" "latticetet --density 0.5 --cells 30 -o fsz/x.msh s64.vdb"; do
    tool=${c%% *}
    out=$(echo "$c" | sed 's/.*-o \(fsz\/[^ ]*\).*/\1/')
    # shellcheck disable=SC2086
    expect_fail "ulimit -f: $tool -o ${out#fsz/}: exit 1, 'File too large'" 1 \
        "^$tool: $out: write failed: File too large" sh -c "ulimit -f 100 && $c"
    [ -z "$(ls -A fsz)" ]
    ok $? "ulimit -f: $tool -o ${out#fsz/}: nothing left"
done

# ---- memory limits -----------------------------------------------------
# The exact need: a -r 48 bunny field is 58x57x47 voxels of 4 bytes.
need=$((58 * 57 * 47 * 4))
expect_fail "soupdist: --max-memory one byte short of the grid: refused, names -r (a value that fits) and --max-memory" 1 \
    "^soupdist: .*bunny.obj: a 58x57x47 grid .*use -r [0-9]+ or less.*--max-memory" \
    soupdist -r 48 --max-memory $((need - 1)) -o x.vdb "$BUNNY"
fit=$(sed -n 's/.*use -r \([0-9]*\) or less.*/\1/p' "$WORK/.err")
check "soupdist: the -r it names ($fit) fits that --max-memory" \
    soupdist -q -r "${fit:-0}" --max-memory $((need - 1)) -o fit.vdb "$BUNNY"
expect_fail "soupdist: and one more voxel does not" 1 "over the limit" \
    soupdist -r $((${fit:-0} + 1)) --max-memory $((need - 1)) -o x.vdb "$BUNNY"
check "soupdist: --max-memory of exactly the grid: made" soupdist -q -r 48 --max-memory $need -o y.vdb "$BUNNY"
for c in "soupsign -o x.vdb d.vdb" "soupwrap -o x.obj s.vdb" \
         "latticetet --density 0.5 -o x.vtu s.vdb" "tetstat --field s.vdb l.vtu"; do
    tool=${c%% *}
    f=$(echo "$c" | grep -o '[ds]\.vdb')
    # shellcheck disable=SC2086
    expect_fail "$tool: a field one byte over --max-memory: refused, names --max-memory" 1 \
        "^$tool: $f: a 58x57x47 grid .*--max-memory" $tool --max-memory $((need - 1)) ${c#* }
done
check "soupsign: --max-memory of exactly the field: signed" soupsign -q --max-memory $need -o y2.vdb d.vdb
expect_fail "tetstat: a mesh over --max-memory: refused, names --max-memory" 1 \
    "^tetstat: l.vtu(:[0-9]+)?: .*--max-memory" tetstat --max-memory 1K l.vtu
expect_fail "tetsmooth: a mesh over --max-memory: refused, names --max-memory" 1 \
    "^tetsmooth: l.vtu(:[0-9]+)?: .*--max-memory" tetsmooth --fair --max-memory 1K -o x.vtu l.vtu
expect_fail "latticetet: a lattice over --max-memory: refused, names --cells and --max-memory" 1 \
    "^latticetet: s.vdb: a lattice of [0-9]+ tets .*--cells.*--max-memory" \
    latticetet --density 0.5 --cells 100 --max-memory 50M -o x.vtu s.vdb
expect_fail "latticetet --sculpt: a lattice over --max-memory: refused" 1 \
    "^latticetet: s.vdb: a lattice of [0-9]+ tets .*--max-memory" \
    latticetet --sculpt --surface "$BUNNY" --cells 100 --max-memory 50M -o x.vtu s.vdb
expect_fail "latticetet --cells 100000 (the most it takes): refused, names --cells" 1 \
    "^latticetet: s.vdb: .*--cells" latticetet --density 0.5 --cells 100000 -o x.vtu s.vdb
expect_fail "soupmesh: a lattice over --max-memory: refused, names --cells" 1 \
    "^soupmesh: .*bunny.obj: --cells 100 lays lattices .*--cells.*--max-memory" \
    soupmesh --cells 100 --voxels 64 --max-memory 200M -o x.vtu "$BUNNY"
expect_fail "soupmesh --cells 4096 (the most it takes): refused, names --max-memory" 1 \
    "^soupmesh: .*bunny.obj: .*--max-memory" soupmesh --cells 4096 -o x.vtu "$BUNNY"
expect_fail "soupdist -r 65536 (the most it takes): refused, names -r" 1 \
    "^soupdist: .*bunny.obj: .*grid needs .*-r" soupdist -r 65536 -o x.vdb "$BUNNY"
expect_fail "soupdist -s 1e-9: the size overflows, checked, names -s" 1 \
    "^soupdist: .*bunny.obj: .*overflows.*-s" soupdist -s 1e-9 -o x.vdb "$BUNNY"
expect_fail "soupwrap --surface -r 65536: refused, names -r" 1 \
    "^soupwrap: .*bunny.obj: .*grid needs .*-r" soupwrap --surface "$BUNNY" -r 65536 -o x.obj
expect_fail "latticetet --size 1e-9: refused, names --size" 1 \
    "^latticetet: s.vdb: .*too many cells.*--size" latticetet --density 0.5 --size 1e-9 -o x.vtu s.vdb
check "no output after the refusals" sh -c "test ! -e x.vdb && test ! -e x.vtu && test ! -e x.obj"

# Before the allocation: with the address space capped (ulimit -v) well
# below the refused size, the refusal still names the limit, where letting
# the allocation happen (a limit above it) gives "out of memory". Not under
# ASan, whose shadow memory needs more address space than any cap.
VLIM=700000
if (ulimit -v $VLIM && soupdist -q -r 16 -o v.vdb "$BUNNY") 2>/dev/null; then
    capped() { (ulimit -v $VLIM && "$@"); }
    # 710x695x545 floats: 1026 MiB
    expect_fail "capped: soupdist -r 700 --max-memory 1000M: refused by the limit" 1 \
        "over the limit of 1000.0 MiB" capped soupdist -r 700 --max-memory 1000M -o x.vdb "$BUNNY"
    # --band full: the dense grid (a finite band into .vdb is built by
    # blocks and fits under the cap)
    expect_fail "capped: soupdist -r 700 --band full --max-memory 2G: the allocation fails, naming ulimit -v" 1 \
        "out of memory.*ulimit -v caps this process's address space at [0-9]+ MiB" \
        capped soupdist -r 700 --band full --max-memory 2G -o x.vdb "$BUNNY"
    # With no --max-memory the default is what ulimit -v leaves, so the
    # estimate refuses the job and names the options, where it was 80% of
    # the RAM and the allocation failed midway ("out of memory").
    expect_fail "capped: soupdist -r 700 (default limit): refused by the estimate, names -r and ulimit -v" 1 \
        "^soupdist: .*bunny.obj: a 710x693x543 grid needs .* over the limit of .*-r.*--max-memory.*ulimit -v leaves" \
        capped soupdist -r 700 -o x.vdb "$BUNNY"
    expect_fail "capped: soupwrap --surface -r 700 (default limit): refused by the estimate" 1 \
        "^soupwrap: .*bunny.obj: a 710x693x543 grid needs .* over the limit of .*-r.*ulimit -v leaves" \
        capped soupwrap --surface "$BUNNY" -r 700 -o x.obj
    expect_fail "capped: latticetet --cells 200 (default limit): refused, names --cells and ulimit -v" 1 \
        "^latticetet: s.vdb: a lattice of .*--cells.*ulimit -v leaves" \
        capped latticetet --density 0.5 --cells 200 -o x.vtu s.vdb
    check "capped: nothing left by the refusals" sh -c "test ! -e x.vdb && test ! -e x.obj && test ! -e x.vtu && ! ls -A | grep -q '\.tmp-'"
    expect_fail "capped: soupwrap --surface -r 700 --max-memory 1000M: refused by the limit" 1 \
        "over the limit of 1000.0 MiB" capped soupwrap --surface "$BUNNY" -r 700 --max-memory 1000M -o x.obj
    # 37 million tets of at least 64 bytes: 2.3 GB
    expect_fail "capped: latticetet --cells 200 --max-memory 1G: refused by the limit" 1 \
        "^latticetet: s.vdb: a lattice of .*--max-memory" \
        capped latticetet --density 0.5 --cells 200 --max-memory 1G -o x.vtu s.vdb
    expect_fail "capped: latticetet --cells 200 --max-memory 1T: the allocation fails" 1 \
        "out of memory" capped latticetet --density 0.5 --cells 200 --max-memory 1T -o x.vtu s.vdb
    expect_fail "capped: soupmesh --cells 250 (default limit): refused before the lattice" 1 \
        "^soupmesh: .*--cells 250 lays lattices" capped soupmesh --cells 250 --voxels 64 -o x.vtu "$BUNNY"
    expect_fail "capped: soupmesh --cells 250 --max-memory 1T: the allocation fails" 1 \
        "out of memory" capped soupmesh --cells 250 --voxels 64 --max-memory 1T -o x.vtu "$BUNNY"
    # Headers that promise more than the file holds are refused before
    # anything of their size is allocated, whatever the limit.
    cat > huge.vti <<'EOF'
<?xml version="1.0"?>
<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <ImageData WholeExtent="0 3000 0 3000 0 3000" Origin="0 0 0" Spacing="1 1 1">
    <Piece Extent="0 3000 0 3000 0 3000">
      <PointData Scalars="sdf">
        <DataArray type="Float32" Name="sdf" format="ascii">1 1 1 1</DataArray>
      </PointData>
    </Piece>
  </ImageData>
</VTKFile>
EOF
    printf '$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 1000000000 1 1000000000\n3 1 0 1000000000\n1\n0 0 0\n$EndNodes\n' > huge.msh
    printf 'OFF\n1000000000 1000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' > huge.off
    for c in "soupsign -o x.vdb huge.vti" "latticetet --density 0.5 -o x.vtu huge.vti" \
             "tetstat huge.msh" "tetsmooth --fair -o x.vtu huge.msh" \
             "soupinfo huge.off" "soupmesh -o x.vtu huge.off"; do
        tool=${c%% *}
        f=huge.vti
        case $c in *msh*) f=huge.msh ;; *off*) f=huge.off ;; esac
        # (soupinfo takes no --max-memory: a soup is bounded by its file)
        [ "$tool" = soupinfo ] || c="$c --max-memory 1T"
        # shellcheck disable=SC2086
        capped $c >/dev/null 2>cap.err
        rc=$?
        [ $rc -eq 1 ] && grep -q "^$tool: $f" cap.err && ! grep -q "out of memory" cap.err
        ok $? "capped: $tool on a header of a billion items: exit 1 naming $f, nothing allocated"
        [ $rc -eq 1 ] || { echo "#   exit $rc"; sed 's/^/#   /' cap.err | head -3; }
    done
else
    skip "limits checked before allocating (ulimit -v)" "ulimit -v $VLIM does not leave room to run (a sanitizer build?)"
fi

# ---- durable output ----------------------------------------------------
# The temporary is fsync'ed before the rename and the directory after it
# (a power cut then leaves the old file or the whole new one), for a
# stream writer (soupwrap -> .obj) and a library that writes by name (VTK
# -> .vtu). strace shows the order of the calls.
durable() {
    name=$1 target=$2
    shift 2
    # (LeakSanitizer cannot run under ptrace: off here, for the sanitize build)
    ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0 \
        strace -f -e trace=fsync,fdatasync,rename,renameat,renameat2 -o "$WORK/trace" "$@" \
        >/dev/null 2>"$WORK/.err"
    awk -v t="\"$target\"" '
        /fsync\(|fdatasync\(/ && /= 0/ { if (state == 0) state = 1; else if (state == 2) state = 3 }
        /rename/ && index($0, t) && /= 0/ { if (state == 1) state = 2 }
        END { exit state == 3 ? 0 : 1 }' "$WORK/trace"
    ok $? "$name: fsync, rename into place, fsync of the directory"
}
durable "soupwrap -o .obj" w.obj soupwrap -q -o w.obj s.vdb
latticetet -q --density 0.5 --cells 6 -o d6.vtu s.vdb
durable "tetsmooth -o .vtu (written by VTK)" f.vtu tetsmooth -q --fair -o f.vtu d6.vtu

done_testing
