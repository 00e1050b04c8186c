#!/bin/sh
# tests/tools/layering.t - the module order of src/MODULES holds: no file
# of the library includes a module further down or calls a function one
# defines (scripts/layering), and the README gives the same order. The
# checker is tried on a copy of the tree with deliberate back-edges too,
# so this test can fail.
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

# The smooth module's order (smooth_mesh -> pgrid -> swept -> invariant
# -> quality -> fit -> fair) through a private header: fit_swept.c (swept)
# including invariant.h fails.
cp "$ROOT"/src/err.c tree/src/err.c
printf '#include "invariant.h"\n' >> tree/src/fit_swept.c
n=$(wc -l < tree/src/fit_swept.c)
"$ROOT/scripts/layering" tree > priv.txt
[ $? -eq 1 ] && grep -q "^src/fit_swept.c:$n: swept includes invariant (after it in src/MODULES)" priv.txt
ok $? "a private header's back-edge (fit_swept.c including invariant.h) fails"
sed 's/^/#   /' priv.txt | head -5
cp "$ROOT"/src/fit_swept.c tree/src/fit_swept.c

# A call the includes do not show: smooth.h (smooth_mesh, the first of
# them) declares st_fit_params_default, which fit.c defines, so quality.c
# calling it includes nothing later, but calls into fit.
printf 'void probe(void)\n{\n    (void)st_fit_params_default();\n}\n' >> tree/src/quality.c
n=$(($(wc -l < tree/src/quality.c) - 1))
"$ROOT/scripts/layering" tree > call.txt
[ $? -eq 1 ] && grep -q "^src/quality.c:$n: quality calls st_fit_params_default, defined in fit (after it in src/MODULES)" call.txt
ok $? "a call into a later module (quality.c calling fit.c's st_fit_params_default) fails"
sed 's/^/#   /' call.txt | head -5
cp "$ROOT"/src/quality.c tree/src/quality.c

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
