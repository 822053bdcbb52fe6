"""What the Python tests of the programs share: their command line (as test/CMakeLists.txt passes
it) and their checks, which print each failure and make the exit status."""
import argparse
import sys

failures = []


def program_arguments(*programs, ranks=None):
    """--<program> for each program's path, --inputs, --workdir and, unless ranks is None,
    --ranks (default `ranks`) and --mpiexec (the launcher as one string)."""
    parser = argparse.ArgumentParser(description=sys.modules["__main__"].__doc__)
    for program in programs:
        parser.add_argument(f"--{program}", required=True, help=f"path of the {program} program")
    if ranks is not None:
        parser.add_argument("--ranks", type=int, default=ranks, help="MPI ranks of every run")
        parser.add_argument("--mpiexec", required=True, help="the MPI launcher and its options")
    parser.add_argument("--inputs", required=True, help="the inputs/ folder")
    parser.add_argument("--workdir", required=True, help="where the runs write their output")
    return parser


def check(condition, message):
    if not condition:
        failures.append(message)
        print("FAIL:", message)


def finish(passed_message=None):
    """Exit 1 after any failed check, else 0 (printing passed_message)."""
    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)
    if passed_message:
        print(passed_message)
    sys.exit(0)
