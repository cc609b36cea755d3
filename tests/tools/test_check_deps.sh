#!/bin/sh
# tests/tools/test_check_deps.sh CHECK_DEPS CC — tools/check_deps on a made
# tree: a folder whose files call one way passes, one whose files call
# each other in a circle (two files, then three) fails naming them, and an
# object whose source was removed is not counted.
set -u
check=$1
cc=${2:-cc}
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
# files NAME:CALLS... : each NAME.c defines NAME() and calls each of CALLS.
make_tree() {
  rm -rf "$t/src" "$t/build"
  mkdir -p "$t/src/geom" "$t/build/CMakeFiles/rayes_geom.dir/src/geom"
  for spec in "$@"; do
    name=${spec%%:*}
    calls=${spec#*:}
    {
      for c in $calls; do echo "int $c(void);"; done
      printf 'int %s(void) { return 0' "$name"
      for c in $calls; do printf ' + %s()' "$c"; done
      echo '; }'
    } > "$t/src/geom/$name.c"
    "$cc" -c "$t/src/geom/$name.c" -o "$t/build/CMakeFiles/rayes_geom.dir/src/geom/$name.c.o" ||
      fail "cannot compile $name.c"
  done
}
make_tree "a:b c" "b:c" "c:"
"$check" "$t" "$t/build" > "$t/out" 2>&1 || fail "one-way calls refused: $(cat "$t/out")"
make_tree "a:b" "b:a" "c:"
"$check" "$t" "$t/build" > "$t/out" 2>&1 && fail "a <-> b passed"
grep -q 'src/geom: files call each other in a circle:.*a\.c.*b\.c' "$t/out" ||
  fail "the circle a <-> b is not named: $(cat "$t/out")"
make_tree "a:b" "b:c" "c:a"
"$check" "$t" "$t/build" > /dev/null 2>&1 && fail "a -> b -> c -> a passed"
make_tree "a:b" "b:a"
"$check" "$t" > /dev/null 2>&1 || fail "without a build directory the include rules alone"
rm "$t/src/geom/b.c"
cc_b="$t/build/CMakeFiles/rayes_geom.dir/src/geom/b.c.o"
[ -f "$cc_b" ] || fail "setup"
"$check" "$t" "$t/build" > "$t/out" 2>&1 || fail "a removed file's object counted: $(cat "$t/out")"
echo "check_deps: one-way passes, circles of 2 and 3 files fail, stale objects ignored"
