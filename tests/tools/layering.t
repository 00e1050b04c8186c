#!/bin/sh
# tests/tools/layering.t - the module order of src/MODULES holds: no file
# of the library includes a module further down (scripts/layering), and
# the README gives the same order. The checker is tried on a copy of the
# tree with a deliberate back-edge too, so this test can fail.
. "$(dirname "$0")/lib.sh"
cd "$WORK" || exit 1

"$ROOT/scripts/layering" "$ROOT" > out.txt
ok $? "no src/*.c, src/*.h, adapter or public header includes a later module"
sed 's/^/#   /' out.txt | head -20

# A copy with err.c including pipeline.h (the last module but a few):
# the checker must name the file, the line and both modules.
mkdir -p tree/src/adapters tree/include
cp -R "$ROOT/include/souptet" tree/include/
cp "$ROOT"/src/*.c "$ROOT"/src/*.h "$ROOT/src/MODULES" tree/src/
cp "$ROOT"/src/adapters/* tree/src/adapters/
cp "$ROOT/README.md" tree/
"$ROOT/scripts/layering" tree > same.txt
ok $? "the copy of the tree passes as the tree does"
printf '#include "souptet/pipeline.h"\n' >> tree/src/err.c
n=$(wc -l < tree/src/err.c)
"$ROOT/scripts/layering" tree > back.txt
[ $? -eq 1 ] && grep -q "^src/err.c:$n: err includes pipeline (after it in src/MODULES)" back.txt
ok $? "a back-edge (err.c including pipeline.h) fails, naming src/err.c:$n"
sed 's/^/#   /' back.txt | head -5

# A module src/MODULES does not list, and a README that disagrees.
cp "$ROOT"/src/err.c tree/src/err.c
printf '/* new */\n' > tree/src/newmod.c
"$ROOT/scripts/layering" tree > new.txt
[ $? -eq 1 ] && grep -q "^src/newmod.c:1: module newmod is not in src/MODULES" new.txt
ok $? "a file of a module missing from src/MODULES fails"
rm tree/src/newmod.c
sed -i 's/err → mem/mem → err/' tree/README.md
"$ROOT/scripts/layering" tree > readme.txt
[ $? -eq 1 ] && grep -q "README.md" readme.txt
ok $? "a README module order that differs from src/MODULES fails"

done_testing
