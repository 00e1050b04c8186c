#!/bin/sh
# tests/tools/blender.t - the Blender add-on (blender/souptet_cage, issue 42):
# the zip make blender-addon builds ($BUILD/souptet_cage.zip, beside
# SOUPTET_BIN) is installed into a temporary user scripts directory and
# enabled in a headless Blender, which runs tests/blender/test_cage.py on
# three soups (clean with a modifier, flipped at random, one-sided with
# loose vertices; each rotated and non-uniformly scaled): the cage is
# closed, outward, encloses every world-space vertex (an independent
# winding-number check in numpy), binds with Mesh Deform and carries the
# mesh along; refusals leave nothing behind. Then, in a window under
# xvfb-run (tests/blender/test_modal.py), the operator as the panel's button
# runs it: in a thread under a modal timer, cancelled by a simulated Esc.
# Their TAP lines are renumbered after ours. Skipped in the sanitizer, fuzz and tsan builds (the Python
# module is not built there, and an ASan library cannot load into Blender).
. "$(dirname "$0")/lib.sh"
cd "$WORK" || exit 1

BUILD=$(cd "$SOUPTET_BIN/.." && pwd)
case "$(basename "$BUILD")" in
    build-sanitize|build-fuzz|build-tsan)
        echo "1..0 # SKIP the Blender add-on's Python extension is not built with the sanitizers ($(basename "$BUILD"))"
        exit 0 ;;
esac

ZIP=$BUILD/souptet_cage.zip
command -v blender >/dev/null 2>&1
ok $? "blender is installed (scripts/setup installs it)"
[ -f "$ZIP" ]
ok $? "the add-on's zip is built ($ZIP: make blender-addon)"
if [ "$TAP_FAILED" -ne 0 ]; then
    done_testing
    exit $?
fi

check "the zip carries the add-on, the module and its core library, no VTK part" \
    sh -c "$PYVTK -m zipfile -l '$ZIP' | grep -q 'souptet_cage/__init__.py' &&
           $PYVTK -m zipfile -l '$ZIP' | grep -q 'souptet_cage/_bundled/souptet/_core' &&
           ! $PYVTK -m zipfile -l '$ZIP' | grep -q '_io'"

# A user scripts directory of our own: the add-on installs there, not
# into ~/.config/blender. No souptet on the path but the bundled one.
mkdir -p scripts config
export BLENDER_USER_SCRIPTS="$WORK/scripts" BLENDER_USER_CONFIG="$WORK/config" PYTHONPATH=

# run_tap NAME OUT ERR RC: OUT's TAP lines renumbered after ours, then
# checks that it ran to its plan and exited 0.
run_tap() {
    grep -E '^(not )?ok [0-9]+|^#' "$2" |
      awk -v n="$TAP_N" '/^(not )?ok [0-9]+/ { n++; sub(/ok [0-9]+/, "ok " n) } { print }'
    TAP_N=$((TAP_N + $(grep -Ec '^(not )?ok [0-9]+' "$2")))
    TAP_FAILED=$((TAP_FAILED + $(grep -Ec '^not ok [0-9]+' "$2")))
    grep -q '^1\.\.[0-9]' "$2"
    ok $? "$1 ran to its end"
    ok "$4" "$1: blender exited 0"
    [ "$4" -eq 0 ] || { sed 's/^/#   /' "$3" | tail -15
                        grep -v -E '^(not )?ok |^#|^1\.\.' "$2" | sed 's/^/#   /' | tail -15; }
}

blender -b --factory-startup --python-exit-code 1 \
  --python "$ROOT/tests/blender/test_cage.py" -- "$ZIP" "$ROOT/corpus/bunny.obj" "$WORK" \
  >cage.out 2>cage.err
run_tap test_cage.py cage.out cage.err $?

# The interactive path (invoke, the modal timer, Esc) needs a window:
# Blender under xvfb-run with its event simulation.
timeout 300 xvfb-run -a -s "-screen 0 1280x800x24" \
  blender --factory-startup --enable-event-simulate \
  --python "$ROOT/tests/blender/test_modal.py" -- "$ZIP" "$ROOT/corpus/bunny.obj" \
  >modal.out 2>modal.err
run_tap test_modal.py modal.out modal.err $?
done_testing
