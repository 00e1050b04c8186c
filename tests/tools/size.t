#!/bin/sh
# tests/tools/size.t - soupmesh -h/--size H: an absolute lattice cell
# width, as latticetet's -h.
. "$(dirname "$0")/lib.sh"
TB=${SOUPTET_TESTBIN:-$ROOT/build/tests}
cd "$WORK" || exit 1
# A tetrahedron whose longest box side is 2: --cells 4 is h = 0.5 exactly.
printf 'OFF\n4 4 0\n0 0 0\n2 0 0\n0 2 0\n0 0 2\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n' >tet.off

check "soupmesh --cells 4" soupmesh -q --cells 4 -o c.vtu tet.off
check "soupmesh --size 0.5" soupmesh -q --size 0.5 -o s.vtu tet.off
check "--size 0.5 is --cells 4 on a box of longest side 2: the same mesh" \
    "$TB/test_tetformat" --compare c.vtu s.vtu
check "-h 0.5 is --size 0.5" sh -c "soupmesh -q -h 0.5 -o h.vtu tet.off && '$TB/test_tetformat' --compare s.vtu h.vtu"
tetstat -q --json s.vtu >s.json && grep -q '"h": 0.5[,}]' s.json
ok $? "the mesh records h = 0.5"
soupmesh -q --size 0.3 --field-cells 32 -o t.vtu tet.off && tetstat -q --json t.vtu >t.json &&
    grep -q '"h": 0.29999999999999999[,}]\|"h": 0.3[,}]' t.json
ok $? "--size 0.3 (not a divisor of the box) keeps h = 0.3"
expect_fail "--cells and --size together are a usage error" 2 \
    "--cells and --size exclude each other" soupmesh --cells 4 --size 1 tet.off
expect_fail "--size 0 is a usage error" 2 "--size wants a number" soupmesh --size 0 tet.off
expect_fail "a width making more than 4096 cells is refused before any work" 1 \
    "tet.off: .*(more than 4096|over the limit)" soupmesh --size 1e-4 -o x.vtu tet.off
[ ! -e x.vtu ]
ok $? "and leaves no output"
done_testing
