#!/bin/sh
# tests/tools/library.t - the shared libraries: libsouptet.so (the C core)
# and libsouptet-io.so (OpenVDB; VTK through its plugin libsouptet-vtk.so.0,
# opened on first use). Sonames; the core needs no C++, OpenVDB or VTK;
# each exports the names its public headers declare and nothing else
# (the core's few private functions that the io library calls only under
# SOUPTET_PRIVATE_0); a program on the public headers,
# linked against the core alone, meshes the bunny and cancels a run; and
# `make install` into a staging directory gives a pkg-config that builds
# the same program.
. "$(dirname "$0")/lib.sh"
BUILD=$(cd "$SOUPTET_BIN/.." && pwd)
cd "$WORK" || exit 1

core="$BUILD/libsouptet.so.0"
io="$BUILD/libsouptet-io.so.0"
[ -f "$core" ] && [ -f "$io" ]
ok $? "build/ has libsouptet.so.0 and libsouptet-io.so.0"

readelf -d "$core" | grep -q 'Library soname: \[libsouptet.so.0\]'
ok $? "libsouptet.so's soname is libsouptet.so.0"
readelf -d "$io" | grep -q 'Library soname: \[libsouptet-io.so.0\]'
ok $? "libsouptet-io.so's soname is libsouptet-io.so.0"

readelf -d "$core" | sed -n 's/.*Shared library: \[\(.*\)\]/\1/p' > needed.txt
! grep -Eq 'vtk|openvdb|tbb|stdc\+\+|Imath' needed.txt
ok $? "the core needs no VTK, OpenVDB, TBB or C++ runtime ($(tr '\n' ' ' < needed.txt))"
readelf -d "$io" | grep -q 'Shared library: \[libsouptet.so.0\]'
ok $? "the io library stands on the core (NEEDED libsouptet.so.0)"
# glTF's JSON is read by the core through jansson; the io library reads
# no JSON of its own, and gets it with the core
readelf -d "$io" | sed -n 's/.*Shared library: \[\(.*\)\]/\1/p' > io-needed.txt
grep -q '^libjansson\.so' needed.txt && ! grep -q jansson io-needed.txt
ok $? "the core needs libjansson (glTF), the io library does not itself"
# soupmesh writes every mesh format in C and reads no field: it loads no
# VTK or OpenVDB (whose relocations cost a process about 60 ms)
readelf -d "$SOUPTET_BIN/soupmesh" | sed -n 's/.*Shared library: \[\(.*\)\]/\1/p' > tool-needed.txt
! grep -Eq 'vtk|openvdb|tbb|Imath' tool-needed.txt
ok $? "soupmesh needs no VTK, OpenVDB or TBB ($(tr '\n' ' ' < tool-needed.txt))"
# VTK is a plugin, libsouptet-vtk.so.0, opened the first time a .vti or
# .vtu is read or a .vti written: no tool, nor the io library, needs it at
# start (soupdist's 37 libraries were 21 then, its start 30 ms shorter)
readelf -d "$SOUPTET_BIN/soupdist" "$io" | grep 'Shared library' > start-needed.txt
! grep -q vtk start-needed.txt && grep -q openvdb start-needed.txt
ok $? "soupdist and libsouptet-io.so need OpenVDB and no VTK at start"
plugin="$BUILD/libsouptet-vtk.so.0"
nm -D --defined-only "$plugin" | awk '$2 != "A" {print $3}' | sed 's/@.*//' | sort -u > plugin-exports.txt
[ "$(cat plugin-exports.txt)" = st_vtk_plugin_entry ] && readelf -d "$plugin" | grep -q 'libvtkIOXML'
ok $? "the plugin exports its table alone and needs VTK ($(tr '\n' ' ' < plugin-exports.txt))"
"$SOUPTET_BIN/soupdist" -q -r 24 -o f.vti "$ROOT/corpus/bunny.obj" &&
    LD_DEBUG=files "$SOUPTET_BIN/soupsign" -q f.vti -o s.vdb 2> ld.txt &&
    grep -q 'file=libsouptet-vtk.so.0 .*dynamically loaded' ld.txt
ok $? "soupsign opens the plugin to read a .vti"

# Exports: every defined dynamic symbol is a public name (declared in
# include/souptet/*.h) or one of the core's private ones the io library
# needs, versioned SOUPTET_PRIVATE_0.
grep -ohw 'st_[A-Za-z0-9_]*' "$ROOT"/include/souptet/*.h | LC_ALL=C sort -u > public.txt
nm -D --defined-only --with-symbol-versions "$core" | awk '{print $3}' | grep -v '^SOUPTET' > core-syms.txt
sed 's/@.*//' core-syms.txt | LC_ALL=C sort -u > core-names.txt
grep '@@SOUPTET_PRIVATE_0' core-syms.txt | sed 's/@.*//' | LC_ALL=C sort -u > core-private.txt
LC_ALL=C comm -23 core-names.txt public.txt > not-public.txt
cmp -s not-public.txt core-private.txt
ok $? "the core exports only public names, and private ones under SOUPTET_PRIVATE_0 ($(wc -l < core-names.txt) symbols, $(wc -l < core-private.txt) private)"
sed 's/^/#   not public: /' not-public.txt | head -5
for f in st_pipeline_run st_soup_read st_tetmesh_write_msh st_dist_field st_pseudo_volume st_embed_points; do
    grep -qx "$f" core-names.txt || echo "$f" >> missing.txt
done
[ ! -s missing.txt ]
ok $? "the core exports the pipeline, the readers, the formats, the field, the pseudo volume, the embedding"
sed 's/^/#   missing: /' missing.txt 2>/dev/null
# st_tf_boundary: tetformat's private boundary finder, used by no io file
! grep -qx 'st_tf_boundary' core-names.txt
ok $? "a private function the io library does not call stays local (st_tf_boundary)"
nm -D --defined-only "$io" | awk '{print $3}' | grep -v '^SOUPTET' | sed 's/@.*//' | LC_ALL=C sort -u > io-names.txt
LC_ALL=C comm -23 io-names.txt public.txt > io-not-public.txt
[ ! -s io-not-public.txt ] && grep -qx st_tetmesh_save io-names.txt && grep -qx st_wrap_field io-names.txt
ok $? "the io library exports only public names (st_tetmesh_save, st_wrap_field, ...: $(wc -l < io-names.txt))"
sed 's/^/#   not public: /' io-not-public.txt | head -5

case "$BUILD" in
*build-sanitize|*build-tsan|*build-fuzz)
    echo "# the rest links a plain program against the library: release and debug builds only"
    done_testing
    exit $? ;;
esac

cat > prog.c <<'EOF'
/* A user's program: the public headers and the core library alone. */
#include <souptet/pipeline.h>
#include <souptet/tetformat.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    st_error err;
    st_soup *s = NULL;
    if (argc < 3 || st_soup_read(&s, argv[1], &err)) {
        fprintf(stderr, "read: %s\n", argc < 3 ? "usage" : err.msg);
        return 1;
    }
    st_pipeline_params p = st_pipeline_params_default();
    p.cells = 5;
    st_tetmesh *m = NULL;
    st_pipeline_stats st;
    if (st_pipeline_run(&m, &st, s, &p, NULL, &err) ||
        st_tetmesh_write_msh(m, argv[2], 0, 0, &err)) {
        fprintf(stderr, "mesh: %s\n", err.msg);
        return 1;
    }
    printf("%zu tets, encloses %d\n", m->ntets, st.encloses);
    free(st.candidates);
    st_tetmesh_free(m);
    /* a run cancelled before it starts */
    volatile int stop = 1;
    st_progress prog = {NULL, NULL, &stop};
    st_status rc = st_pipeline_run(&m, &st, s, &p, &prog, &err);
    printf("cancelled: %s\n", rc == ST_ECANCELLED && !m ? "yes" : "no");
    free(st.candidates);
    st_soup_free(s);
    return 0;
}
EOF
cc -std=c11 -I"$ROOT/include" prog.c -L"$BUILD" -lsouptet -Wl,-rpath,"$BUILD" -Wall -Werror -o prog 2> cc.err
ok $? "a C program on the public headers links against -lsouptet alone"
sed 's/^/#   /' cc.err | head -5
readelf -d prog | grep -q 'Shared library: \[libsouptet.so.0\]' &&
    ! readelf -d prog | grep -q 'libsouptet-io'
ok $? "it needs libsouptet.so.0 and not the io library"
./prog "$ROOT/corpus/bunny.obj" bunny.msh > prog.out 2> prog.err
ok $? "it meshes the bunny"
sed 's/^/#   /' prog.out prog.err | head -5
grep -q 'encloses 1' prog.out && grep -q 'cancelled: yes' prog.out
ok $? "the mesh encloses, and a cancelled run returns ST_ECANCELLED"
gmsh -check bunny.msh > gmsh.out 2>&1
ok $? "gmsh reads the program's .msh"

# make install into a staging directory; pkg-config builds the program.
make -C "$ROOT" --no-print-directory -s install PREFIX=/usr DESTDIR="$WORK/stage" > install.out 2>&1
ok $? "make install PREFIX=/usr DESTDIR=stage"
sed 's/^/#   /' install.out | tail -5
lib="$WORK/stage/usr/lib"
[ -f "$lib/libsouptet.so.0" ] && [ -L "$lib/libsouptet.so" ] && [ -f "$lib/libsouptet-io.so.0" ] &&
    [ -f "$lib/pkgconfig/souptet.pc" ] && [ -f "$lib/pkgconfig/souptet-io.pc" ]
ok $? "it installs both libraries, their sonames and links, and souptet.pc, souptet-io.pc"
flags=$(PKG_CONFIG_SYSROOT_DIR="$WORK/stage" PKG_CONFIG_LIBDIR="$lib/pkgconfig" \
        pkg-config --cflags --libs souptet)
ok $? "pkg-config --cflags --libs souptet: $flags"
# shellcheck disable=SC2086
cc -std=c11 prog.c $flags -Wl,-rpath,"$lib" -o prog2 2> cc2.err && ./prog2 "$ROOT/corpus/bunny.obj" b2.msh > prog2.out
ok $? "the program builds from the installed headers and library through pkg-config"
sed 's/^/#   /' cc2.err | head -5

# The Python module: where Debian's python3 looks for PREFIX=/usr, and it
# imports from there (the staged libraries through LD_LIBRARY_PATH, as
# they would be in /usr/lib).
site="$WORK/stage/usr/lib/python3/dist-packages"
if [ -d "$BUILD/python/souptet" ]; then
    (cd "$WORK" && PYTHONPATH="$site" LD_LIBRARY_PATH="$lib" /usr/bin/python3 -c \
        'import souptet, sys; m = souptet.mesh(*souptet.read(sys.argv[1]), cells=4, tries=1); assert m.encloses; print(souptet.__file__)' \
        "$ROOT/corpus/bunny.obj") > py.out 2>&1 && grep -q "^$site/souptet/__init__.py" py.out
    ok $? "make install PREFIX=/usr puts the Python module in /usr/lib/python3/dist-packages, and it meshes from there"
    sed 's/^/#   /' py.out | tail -3
    /usr/bin/python3 -c 'import sys; sys.exit(0 if "/usr/local/lib/python%d.%d/dist-packages" % sys.version_info[:2] in sys.path else 1)'
    ok $? "and PREFIX=/usr/local's place (/usr/local/lib/python3.X/dist-packages) is on Debian's python3 path"
fi

# The link line is recorded like the compile flags ($(BUILD)/linkflags): a
# built tree relinks when a library or link option changes, and only then.
# On a tree of symbolic links to this build (make reads the targets' times
# through them), with the generated records made afresh and dated old.
cp -as "$BUILD" "$WORK/lb" 2>/dev/null
rm -f "$WORK/lb/flags" "$WORK/lb/linkflags" "$WORK/lb/gen/souptet_build.h"
mk() { env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -C "$ROOT" -q --no-print-directory \
           config=release BUILD="$WORK/lb" "$WORK/lb/bin/soupinfo" "$@" >/dev/null 2>&1; }
mk
touch -d 2000-01-01 "$WORK/lb/flags" "$WORK/lb/linkflags" "$WORK/lb/gen/souptet_build.h"
mk; up=$?
mk OMPLIB='-lgomp -ldl'; changed=$?
[ "$up" = 0 ] && [ "$changed" = 1 ]
ok $? "soupinfo is up to date with the link line it was made with, and relinks when a library changes (make -q: $up, $changed)"
grep -q -- '-lgomp -ldl' "$WORK/lb/linkflags"
ok $? "the new link line is recorded in linkflags"

done_testing
