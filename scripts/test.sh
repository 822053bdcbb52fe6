#!/usr/bin/env bash
# Builds viscompm (installing what is missing) and runs the whole test suite with ctest, the MPI
# tests at their registered rank counts included. Extra arguments go to ctest (e.g. -L unit).
#
#   scripts/test.sh                     build/ and every test
#   scripts/test.sh --sanitize [-L ..]  build-sanitize/ with AddressSanitizer and
#                                       UndefinedBehaviorSanitizer, leaks checked, the known leaks
#                                       of MPI and Trilinos suppressed (scripts/sanitizers/)
#   scripts/test.sh --no-trilinos       only the tests of the physics layer (label no_trilinos),
#                                       building only them (with --sanitize: 10 min from cold)
#
# An option that is neither test.sh's nor ctest's (a typo such as --sanitise) is one line on
# stderr naming it, exit 2, before anything is built.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ctest_args=()
sanitize=0
ctest_help=""
for argument in "$@"; do
  case "$argument" in
    -h|--help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --sanitize) sanitize=1 ;;
    --no-trilinos) export VISCOMPM_BUILD_TARGET=no_trilinos_tests; ctest_args+=(-L no_trilinos) ;;
    -*)
      # ctest's options as its --help lists them ("-j2" is -j, "--timeout=5" is --timeout).
      [ -n "$ctest_help" ] || ctest_help="$(ctest --help 2>/dev/null || true)"
      option="${argument%%=*}"
      [[ "$option" == --* ]] || option="${option:0:2}"
      grep -q -e "^ *${option}[ ,<=]" -e "^ *${option}\$" -e ", *${option}[ ,<=]" <<< "$ctest_help" ||
        { echo "test.sh: unknown option '$argument' (test.sh's: --sanitize, --no-trilinos; the rest go to ctest)" >&2; exit 2; }
      ctest_args+=("$argument") ;;
    *) ctest_args+=("$argument") ;;
  esac
done
if [ "$sanitize" = 1 ]; then
  export VISCOMPM_BUILD_DIR="${VISCOMPM_BUILD_DIR:-$here/../build-sanitize}"
  export VISCOMPM_CMAKE_ARGS="${VISCOMPM_CMAKE_ARGS:-} -DVISCOMPM_SANITIZE=ON"
  # Every error stops the program (exit 1 from the sanitizers' report); leaks are reported at
  # exit, except those listed (each explained) in the suppression files.
  suppressions="$here/sanitizers"
  export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:verify_asan_link_order=0:suppressions=$suppressions/asan.supp"
  export LSAN_OPTIONS="suppressions=$suppressions/lsan.supp:print_suppressions=0"
  export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:suppressions=$suppressions/ubsan.supp"
fi
source "$here/setup.sh"

cd "$BUILD_DIR"
ctest --output-on-failure -j "$JOBS" ${ctest_args[@]+"${ctest_args[@]}"}
