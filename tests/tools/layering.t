#!/bin/sh
# tests/tools/layering.t - the module order of src/MODULES holds: no file
# of the library includes a module further down or calls a function one
# defines (scripts/layering), every file sits in its module's layer folder
# src/LAYER/, and the README gives the same module and layer orders. The checker is tried on a copy of the
# tree with deliberate faults too, so this test can fail; scripts/layout
# is tried on a copy in git with a module moved to another layer.
. "$(dirname "$0")/lib.sh"
cd "$WORK" || exit 1

"$ROOT/scripts/layering" "$ROOT" > out.txt
ok $? "no library file or public header includes a later module; each file is in its layer's folder"
sed 's/^/#   /' out.txt | head -20

mkdir -p tree/include
cp -R "$ROOT/include/souptet" tree/include/
cp -R "$ROOT/src" tree/
cp "$ROOT/README.md" tree/
"$ROOT/scripts/layering" tree > same.txt
ok $? "the copy of the tree passes as the tree does"

# err.c including pipeline.h (a module far down): the checker must name
# the file, the line and both modules.
E=$(cd tree && find src -name err.c)
printf '#include "souptet/pipeline.h"\n' >> "tree/$E"
n=$(wc -l < "tree/$E")
"$ROOT/scripts/layering" tree > back.txt
[ $? -eq 1 ] && grep -q "^$E:$n: err includes pipeline (after it in src/MODULES)" back.txt
ok $? "a back-edge (err.c including pipeline.h) fails, naming $E:$n"
sed 's/^/#   /' back.txt | head -5
cp "$ROOT/$E" "tree/$E"

# The smooth module's order (smooth_mesh -> pgrid -> swept -> invariant
# -> quality -> fit -> fair) through a private header: fit_swept.c (swept)
# including invariant.h fails.
F=$(cd tree && find src -name fit_swept.c)
printf '#include "invariant.h"\n' >> "tree/$F"
n=$(wc -l < "tree/$F")
"$ROOT/scripts/layering" tree > priv.txt
[ $? -eq 1 ] && grep -q "^$F:$n: swept includes invariant (after it in src/MODULES)" priv.txt
ok $? "a private header's back-edge (fit_swept.c including invariant.h) fails"
cp "$ROOT/$F" "tree/$F"

# A call the includes do not show: smooth.h (smooth_mesh, the first of
# them) declares st_fit_params_default, which fit.c defines, so quality.c
# calling it includes nothing later, but calls into fit.
Q=$(cd tree && find src -name quality.c)
printf 'void probe(void)\n{\n    (void)st_fit_params_default();\n}\n' >> "tree/$Q"
n=$(($(wc -l < "tree/$Q") - 1))
"$ROOT/scripts/layering" tree > call.txt
[ $? -eq 1 ] && grep -q "^$Q:$n: quality calls st_fit_params_default, defined in fit" call.txt
ok $? "a call into a later module (quality.c calling fit.c's st_fit_params_default) fails"
sed 's/^/#   /' call.txt | head -3
cp "$ROOT/$Q" "tree/$Q"

# A module src/MODULES does not list.
printf '/* new */\n' > tree/src/newmod.c
"$ROOT/scripts/layering" tree > new.txt
[ $? -eq 1 ] && grep -q "^src/newmod.c:1: module newmod is not in src/MODULES" new.txt
ok $? "a file of a module missing from src/MODULES fails"
rm tree/src/newmod.c

# A file outside its layer's folder: err.c in src/geom/.
mkdir -p tree/src/geom
mv "tree/$E" tree/src/geom/err.c
"$ROOT/scripts/layering" tree > place.txt
[ $? -eq 1 ] && grep -q "^src/geom/err.c:1: module err belongs in src/base/" place.txt
ok $? "a file outside its module's layer folder fails"
sed 's/^/#   /' place.txt | head -3
mv tree/src/geom/err.c "tree/$E"

# A layer given twice (its modules would not be one run).
cp tree/src/MODULES MODULES.orig
printf '[base]\nlate\n' >> tree/src/MODULES
"$ROOT/scripts/layering" tree > twice.txt
[ $? -eq 1 ] && grep -q "layer \[base\] comes twice" twice.txt
ok $? "a layer that comes twice in src/MODULES fails"
cp MODULES.orig tree/src/MODULES

# A README whose module or layer order differs.
cp tree/README.md README.orig
sed -i 's/err → mem/mem → err/' tree/README.md
"$ROOT/scripts/layering" tree > readme.txt
[ $? -eq 1 ] && grep -q "README.md:1: its module order" readme.txt
ok $? "a README module order that differs from src/MODULES fails"
cp README.orig tree/README.md
sed -i 's/base → geom/geom → base/' tree/README.md
"$ROOT/scripts/layering" tree > readme2.txt
[ $? -eq 1 ] && grep -q "README.md:1: its layer order" readme2.txt
ok $? "a README layer order that differs from src/MODULES fails"
cp README.orig tree/README.md

# scripts/layout on the copy in git: radix moves from base to geom (its
# [geom] line above it), with the includes and mentions that reach it.
R=$(cd tree && find src -name radix.h)
printf 'the sort: %s.\n' "$R" > tree/NOTES
G() { git -C tree -c user.name=t -c user.email=t "$@"; }
G init -q && G add -A && G commit -qm tree
sed -i -e '/^\[geom\]/d' -e 's/^radix /[geom]\nradix /' tree/src/MODULES
"$ROOT/scripts/layout" tree > layout.txt 2> layout.err
ok $? "scripts/layout runs"
sed 's/^/#   /' layout.err | head -5
[ -f tree/src/geom/radix.h ] && [ ! -e "tree/$R" ]
ok $? "radix.h moved from $R to src/geom/"
grep -q '^the sort: src/geom/radix.h\.$' tree/NOTES
ok $? "a mention of its path follows ($(cat tree/NOTES))"
"$ROOT/scripts/layering" tree > after.txt
ok $? "the moved tree passes scripts/layering"
sed 's/^/#   /' after.txt | head -5
# A source file that includes the moved header (any one: its includer
# changes with the code).
ED=$(cd tree && grep -rl '^#include ".*radix\.h"' src --include=*.c | sort | head -1)
[ -n "$ED" ] || ED=src/none.c
grep -q '^#include "\.\./geom/radix\.h"' "tree/$ED" &&
    ${CC:-cc} -std=c11 -D_POSIX_C_SOURCE=200809L -Itree/include -fopenmp -fsyntax-only "tree/$ED"
ok $? "$ED includes ../geom/radix.h and compiles with -Iinclude alone"
G add -A && G commit -qm moved
"$ROOT/scripts/layout" tree > again.txt 2>&1 && grep -q '^layout: 0 file(s) to move$' again.txt &&
    [ -z "$(G status --porcelain)" ]
ok $? "a second run does nothing"

# A file it cannot place: an error naming it, and nothing moved.
printf '/* new */\n' > tree/src/newmod.c
G add -A
"$ROOT/scripts/layout" tree > none.txt 2> none.err
[ $? -eq 1 ] && grep -q "^layout: src/newmod.c: module newmod is not in src/MODULES" none.err &&
    [ -f tree/src/geom/radix.h ]
ok $? "a file of a module missing from src/MODULES stops it, named, before any move"
sed 's/^/#   /' none.err | head -3

done_testing
