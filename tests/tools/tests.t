#!/bin/sh
# tests/tools/tests.t - the unit test programs themselves (issue 39, item
# 7): each lists its tests with --list, runs the ones named on its command
# line (in the order given, with a plan that counts what ran), refuses an
# unknown name or option with exit 2 naming it, and finds its fixtures in
# tests/data from any directory.
. "$(dirname "$0")/lib.sh"
cd "$WORK" || exit 1
TB=${SOUPTET_TESTBIN:-$ROOT/build/tests}

# Every program: --list prints names (one a line, no duplicates), and an
# unknown name is refused before anything runs.
for p in "$TB"/test_*; do
    n=$(basename "$p")
    "$p" --list >list.txt 2>list.err
    rc=$?
    [ $rc -eq 0 ] && [ -s list.txt ] && ! [ -s list.err ] &&
        ! grep -Eqv '^[A-Za-z0-9_-]+$' list.txt &&
        [ "$(sort list.txt | uniq -d | wc -l)" -eq 0 ]
    ok $? "$n --list: $(wc -l <list.txt) names, exit $rc"
    "$p" no_such_test >none.out 2>none.err
    rc=$?
    [ $rc -eq 2 ] && ! [ -s none.out ] && grep -q "'no_such_test'" none.err
    ok $? "$n no_such_test: exit 2, named, nothing run (exit $rc)"
done

# One name, then two: only those run, in the order given; the plan counts
# their checks. (Quick tests, some reading fixtures.)
one() {   # one PROGRAM NAME...: run them; ok when exactly those ran
    p=$1
    shift
    "$TB/$p" "$@" >run.out 2>run.err
    rc=$?
    ran=$(sed -n 's/^# \([A-Za-z0-9_-]*\)$/\1/p' run.out | tr '\n' ' ')
    checks=$(grep -Ec '^(not )?ok [0-9]+ ' run.out)
    plan=$(sed -n 's/^1\.\.\([0-9]*\)$/\1/p' run.out)
    [ $rc -eq 0 ] && [ "$ran" = "$* " ] && [ "$checks" -gt 0 ] && [ "$plan" = "$checks" ] &&
        ! grep -q '^not ok' run.out
    ok $? "$p $*: ran '$ran', $checks checks, plan 1..$plan, exit $rc"
}
one test_geom segment
one test_pred drop_axes collinear_perturbed
one test_soup off
one test_solid sphere boxes
one test_shells open_pieces
one test_pipeline candidate_seed empty_soup

# The same test from another directory: the fixtures are found beside the
# program (build/tests/../../tests/data), not in the working directory.
mkdir -p elsewhere && cd elsewhere || exit 1
one test_solid sphere
cd "$WORK" || exit 1

# The fixture is what the test reads: without it the program stops
# ("Bail out!", non-zero), it does not fall back to a built-in shape.
mkdir -p empty
SOUPTET_TESTDATA=$WORK/empty "$TB/test_solid" sphere >bail.out 2>&1
rc=$?
[ $rc -ne 0 ] && grep -q '^Bail out! add_sphere: .*sphere_uv32x16.off' bail.out
ok $? "test_solid sphere without tests/data: Bail out! naming the fixture (exit $rc)"

# An option that is not --list (or a special mode of its own) is refused.
"$TB/test_geom" --frobnicate >opt.out 2>opt.err
rc=$?
[ $rc -eq 2 ] && ! [ -s opt.out ] && grep -q "unknown option '--frobnicate'" opt.err
ok $? "test_geom --frobnicate: exit 2, named (exit $rc)"

done_testing
