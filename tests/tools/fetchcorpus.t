#!/bin/sh
# tests/tools/fetchcorpus.t - scripts/fetch-corpus exits 1 when a model
# cannot be fetched (it used to lose the status in a pipe's subshell and
# exit 0) and still fetches the others. No network: apt-get and npm are
# stand-ins on PATH, and the script runs in a copy of the tree with its own
# manifest (FETCH_CORPUS names another script to test, e.g. an old one).
. "$(dirname "$0")/lib.sh"
cd "$WORK" || exit 1
SCRIPT=${FETCH_CORPUS:-$ROOT/scripts/fetch-corpus}

mkdir -p tree/scripts tree/corpus fake pkg/package
cp "$SCRIPT" tree/scripts/fetch-corpus
printf 'OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n' \
    >pkg/package/tet.off
# npm pack PKG: a tarball of pkg/ in the current directory; apt-get: fails.
cat >fake/npm <<EOF2
#!/bin/sh
[ "\$1" = pack ] || exit 1
tar czf "\$(echo "\$2" | tr '@/' '__').tgz" -C "$WORK/pkg" package
EOF2
printf '#!/bin/sh\necho "E: no network here" >&2\nexit 100\n' >fake/apt-get
chmod +x fake/npm fake/apt-get

T='	'
manifest() {
    printf '# name%ssource%spackage%spath%sformat\n' "$T" "$T" "$T" "$T"
    for line in "$@"; do printf '%s\n' "$line"; done
} 
good="good${T}npm${T}good@1.0.0${T}package/tet.off${T}off${T}4${T}4${T}closed${T}CC0"
bad="bad${T}deb${T}no-such-package${T}data/x.off${T}off${T}-${T}-${T}-${T}-"
odd="odd${T}ftp${T}x${T}x.off${T}off${T}-${T}-${T}-${T}-"

run() {   # run CACHE ARGS...: exit status in $rc, messages in err
    c=$1
    shift
    PATH="$WORK/fake:$PATH" SOUPTET_CORPUS_CACHE="$WORK/$c" \
        sh tree/scripts/fetch-corpus "$@" </dev/null >out 2>err
    rc=$?
}

manifest "$good" >tree/corpus/manifest.tsv
run c1
[ $rc -eq 0 ] && cmp -s c1/models/good.off pkg/package/tet.off
ok $? "every model fetched: exit 0, the model in the cache"
[ $rc -eq 0 ] || sed 's/^/#   /' err

manifest "$bad" "$good" >tree/corpus/manifest.tsv
run c2
[ $rc -eq 1 ] && grep -q 'apt-get download no-such-package failed' err
ok $? "a Debian package that cannot be downloaded: exit 1 (the old script exited 0)"
[ $rc -eq 1 ] || { echo "#   exit $rc"; sed 's/^/#   /' err; }
cmp -s c2/models/good.off pkg/package/tet.off && [ ! -e c2/models/bad.off ]
ok $? "the model after the failed one is still fetched"
[ -z "$(ls -A c2/models | grep -v '^good\.off$')" ] && ! ls -A c2/packages | grep -q '^\.dl\.'
ok $? "nothing half-made is left (no temporary model, no download directory)"

run c2
[ $rc -eq 1 ]
ok $? "run again: the cached model is skipped, the failed one fails again (exit 1)"

run c3 good
[ $rc -eq 0 ] && [ -e c3/models/good.off ] && [ ! -e c3/models/bad.off ]
ok $? "naming only the good model: exit 0"

manifest "$odd" "$good" >tree/corpus/manifest.tsv
run c4
[ $rc -eq 1 ] && grep -q 'odd: unknown source ftp' err && [ -e c4/models/good.off ]
ok $? "a model with an unknown source: exit 1, the others fetched"

run c5 nosuch
[ $rc -eq 1 ] && grep -q 'nosuch: not in corpus/manifest.tsv' err
ok $? "a name that is not in the manifest: exit 1, said"

done_testing
