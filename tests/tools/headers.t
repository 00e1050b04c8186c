#!/bin/sh
# tests/tools/headers.t - every public header opens with the same contract
# block (issue 39, item 4), so it cannot drift:
#
#   /*
#    * NAME.h - what it does (one paragraph, with the paper's section)
#    *
#    * Units: ...
#    * Ownership: ...
#    * Threads: ...
#    * Errors: ...
#    *
#    * (the rest: conventions, or a link to doc/design/NAME.md)
#    */
#
# The four headings start lines of the top comment in that order, within
# its first 40 lines; every doc/design/*.md a header names exists.
. "$(dirname "$0")/lib.sh"
cd "$WORK" || exit 1

n=0
for h in "$ROOT"/include/souptet/*.h; do
    name=$(basename "$h")
    n=$((n + 1))
    # The top comment: from line 1 to the first " */".
    awk 'NR == 1 && $0 != "/*" { exit 1 } { print } /^ \*\/$/ { exit 0 }' "$h" >top.txt
    rc=$?
    [ $rc -eq 0 ] && sed -n 2p top.txt | grep -q "^ \\* $name - "
    ok $? "$name: opens with '/*' and ' * $name - what it does'"
    got=$(head -40 top.txt | sed -n 's/^ \* \(Units\|Ownership\|Threads\|Errors\): .*/\1/p' | tr '\n' ' ')
    [ "$got" = "Units Ownership Threads Errors " ]
    ok $? "$name: Units, Ownership, Threads, Errors at the top, in order (${got:-none})"
    before=$(grep -n '^ \* Units: ' top.txt | head -1 | cut -d: -f1)
    [ -n "$before" ] && [ "$(sed -n "$((before - 1))p" top.txt)" = " *" ]
    ok $? "$name: the contract block stands apart from the paragraph above it"
    missing=
    for d in $(grep -o 'doc/design/[A-Za-z0-9_-]*\.md' "$h" | sort -u); do
        [ -f "$ROOT/$d" ] || missing="$missing $d"
    done
    [ -z "$missing" ]
    ok $? "$name: the design notes it names exist${missing:+ (missing:$missing)}"
done
[ $n -ge 30 ]
ok $? "$n public headers checked"

done_testing
