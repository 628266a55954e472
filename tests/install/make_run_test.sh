#!/usr/bin/env bash
# make_run_test.sh - what `make run` builds and how the build speaks (README, "Two commands").
#
# `make run` builds only the programs tests/run_example.sh starts (poro-server, poro-worker, poro,
# poro-solve, terzaghi-error), not the test programs, with one job per core; `make test` still
# builds every test program. Both are read from `make -n` into an empty build directory, which
# prints every command the build would run without running one (the sub-make line is run, as make
# does for $(MAKE), and prints its own commands). One object is then really compiled to see the
# output: one short line "  CC      TARGET" per file, the whole command with V=1.
# The make variables of the make that runs this test are cleared, so the checks see a make started
# from a shell, as a user starts it.
#   bash tests/install/make_run_test.sh BUILD_DIR      (from the repository root)
set -u
cd "$(dirname "$0")/../.."
unset MAKEFLAGS MFLAGS MAKELEVEL MAKEOVERRIDES
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
b="$tmp/b"

check() { # name, condition exit status (0 = holds), why
	if [ "$2" -eq 0 ]; then echo "PASS $1"; else echo "FAIL $1: $3"; fi
}

# ---- make run: the programs it starts, nothing more, one job per core ------------------------------
make -n run BUILD="$b" > "$tmp/run.txt" 2>&1
check make_n_run_exits_0 $? "$(tail -3 "$tmp/run.txt")"
jobs=$(nproc)
grep -q -- "--no-print-directory -j$jobs build-run" "$tmp/run.txt"
check make_run_builds_with_one_job_per_core $? "no sub-make with -j$jobs: $(grep -m1 'make ' "$tmp/run.txt")"
# the programs linked: every "-o $b/NAME" of a link line (objects end in .o)
linked=$(grep -oE -- "-o $b/[^ ]+" "$tmp/run.txt" | sed "s|-o $b/||" | grep -v '\.o$' | sort | tr '\n' ' ')
want="poro poro-server poro-solve poro-worker terzaghi-error "
[ "$linked" = "$want" ]
check make_run_links_only_what_it_runs $? "links '$linked', expected '$want'"
grep -qE -- "-o $b/(tests|bench)/" "$tmp/run.txt"
check make_run_builds_no_test_program $(( $? == 0 )) \
	"builds $(grep -oE -- "-o $b/(tests|bench)/[^ ]+" "$tmp/run.txt" | head -3 | tr '\n' ' ')"
grep -q "tests/run_example.sh $b" "$tmp/run.txt"
check make_run_runs_the_example $? "$(tail -2 "$tmp/run.txt")"

# ---- make test: still every test program ------------------------------------------------------------
make -n test BUILD="$b" > "$tmp/test.txt" 2>&1
want_tests=$(ls tests/solver/*_test.c tests/verify/*_test.c tests/common/*_test.c | wc -l)
got_tests=$(grep -oE -- "-o $b/tests/[a-z]+/[a-z0-9_]+_test( |$)" "$tmp/test.txt" | sort -u | wc -l)
[ "$got_tests" -eq "$want_tests" ] && grep -q -- "-o $b/poro-server" "$tmp/test.txt"
check make_test_builds_every_test_program $? "links $got_tests test programs of $want_tests"

# ---- one short line per file; V=1 the whole command -------------------------------------------------
make BUILD="$b" "$b/common/digest.o" > "$tmp/quiet.txt" 2>&1
printf '  CC      %s\n' "$b/common/digest.o" | cmp -s - "$tmp/quiet.txt"
check build_prints_one_short_line_per_file $? "printed: $(head -c 300 "$tmp/quiet.txt")"
rm -f "$b/common/digest.o"
make BUILD="$b" V=1 "$b/common/digest.o" > "$tmp/verbose.txt" 2>&1
grep -q -- "-c common/digest.c -o $b/common/digest.o" "$tmp/verbose.txt" && ! grep -q '^  CC ' "$tmp/verbose.txt"
check build_v1_prints_whole_commands $? "printed: $(head -c 300 "$tmp/verbose.txt")"
