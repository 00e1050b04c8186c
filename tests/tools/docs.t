#!/bin/sh
# tests/tools/docs.t - what the tools say matches what they do: the
# defaults and formats in --help and the man pages, the hints, and a
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

# A terminal on stdin: refused at once (exit 2), as a terminal on stdout
# is, instead of waiting silently. script(1) gives the tool a terminal.
if command -v script >/dev/null 2>&1; then
    for cmd in "soupinfo" "tetstat" "soupdist -o x.vdb" "soupmesh -o x.vtu -"; do
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
