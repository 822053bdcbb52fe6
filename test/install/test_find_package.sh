#!/usr/bin/env bash
# find_package(viscompm) from the install tree: installs the build tree into a fresh prefix,
# configures and builds test/install/consumer against it (nothing of the source or build tree on
# its paths), and runs its programs, which check what they compute.
#   test_find_package.sh BUILD_DIR WORK_DIR
set -euo pipefail
build="$1"
work="$2"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
rm -rf "$work"
mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >/dev/null
test -x "$work/prefix/bin/viscompm" && test -x "$work/prefix/bin/viscompm-study"
test -f "$work/prefix/share/viscompm/scripts/plot_study.py"
cmake -S "$here/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/consumer" -j 2 >/dev/null
"$work/consumer/consumer_physics"
"$work/consumer/consumer_scene"
# The installed program runs from the prefix (its help lists the scene parameters).
"$work/prefix/bin/viscompm" --help > "$work/help.txt"
grep -q "Weissenberg number" "$work/help.txt"
echo "find_package(viscompm) works from $work/prefix"
