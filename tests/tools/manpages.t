#!/bin/sh
# Every tool has a man page, and its OPTIONS section and its --help name
# the same long options: a test that fails when the two drift apart.
. "$(dirname "$0")/lib.sh"
cd "$WORK" || exit 1

for tool in soupdist soupsign soupinfo soupwrap latticetet tetsmooth tetstat soupmesh; do
    page="$ROOT/man/man1/$tool.1"
    check "$tool: man page exists and renders without warnings" sh -c \
        "test -s '$page' && LC_ALL=C MANWIDTH=80 man --warnings -l '$page' 2>warn >/dev/null && ! test -s warn"
    # The options a tool lists are its lines that start with one (examples
    # name other tools' options); a man page's are its .TP item lines.
    "$tool" --help | grep -E '^ +(-[a-zA-Z], )?--[a-z]' |
        sed -E 's/^ +(-[a-zA-Z], )?(--[a-z][a-z0-9-]*).*/\2/' | sort -u > help.opts
    sed -n '/^\.SH OPTIONS/,/^\.SH /p' "$page" | awk 'p { print; p = 0 } /^\.TP/ { p = 1 }' |
        sed 's/\\-/-/g' | grep -oE -- '--[a-z][a-z0-9-]+' | sort -u > man.opts
    missing=$(comm -23 help.opts man.opts | tr '\n' ' ')
    extra=$(comm -13 help.opts man.opts | tr '\n' ' ')
    [ -z "$missing" ]
    ok $? "$tool: every option of --help is in the man page's OPTIONS${missing:+ (missing: $missing)}"
    [ -z "$extra" ]
    ok $? "$tool: every option in the man page's OPTIONS is in --help${extra:+ (not in --help: $extra)}"
done
check "souptet(7) exists and renders without warnings" sh -c \
    "LC_ALL=C MANWIDTH=80 man --warnings -l '$ROOT/man/man7/souptet.7' 2>warn >/dev/null && ! test -s warn"

done_testing
