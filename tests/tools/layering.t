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
# refused NAME LINE DESCRIPTION: the checker fails on the copy and names
# LINE (a grep pattern); NAME.txt keeps what it said. Then the copy is
# the tree again.
refused() {
    "$ROOT/scripts/layering" tree > "$1.txt"
    [ $? -eq 1 ] && grep -q "$2" "$1.txt"
    ok $? "$3"
    sed 's/^/#   /' "$1.txt" | head -5
    cp "$ROOT"/src/*.c tree/src/
}

printf '#include "souptet/pipeline.h"\n' >> tree/src/err.c
n=$(wc -l < tree/src/err.c)
refused back "^src/err.c:$n: err includes pipeline (after it in src/MODULES)" \
    "a back-edge (err.c including pipeline.h) fails, naming src/err.c:$n"

# The smooth module's order (smooth_mesh -> pgrid -> swept -> invariant
# -> quality -> fit -> fair) through a private header: fit_swept.c (swept)
# including invariant.h fails.
printf '#include "invariant.h"\n' >> tree/src/fit_swept.c
n=$(wc -l < tree/src/fit_swept.c)
refused priv "^src/fit_swept.c:$n: swept includes invariant (after it in src/MODULES)" \
    "a private header's back-edge (fit_swept.c including invariant.h) fails"

# A call the includes do not show: smooth.h (smooth_mesh, the first of
# them) declares st_fit_params_default, which fit.c defines, so quality.c
# calling it includes nothing later, but calls into fit.
printf 'void probe(void)\n{\n    (void)st_fit_params_default();\n}\n' >> tree/src/quality.c
n=$(($(wc -l < tree/src/quality.c) - 1))
refused call "^src/quality.c:$n: quality calls st_fit_params_default, defined in fit" \
    "a call into a later module (quality.c calling fit.c's st_fit_params_default) fails"

# A module src/MODULES does not list, and a README that disagrees.
printf '/* new */\n' > tree/src/newmod.c
refused new "^src/newmod.c:1: module newmod is not in src/MODULES" \
    "a file of a module missing from src/MODULES fails"
rm tree/src/newmod.c
sed -i 's/err → mem/mem → err/' tree/README.md
refused readme "README.md" "a README module order that differs from src/MODULES fails"

done_testing
