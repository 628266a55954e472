#!/usr/bin/env bash
# plot_test.sh - drives poro-plot (cli/poro_plot.py) on real runs: the Terzaghi column, double and
# single point, shortened to 0.1 s with a frame every 0.025 s, and the k = 1e-3 Mohr-Coulomb slope
# shortened to 0.1 s (its polygon bodies give the run-out picture); then on bad input.
#
# Checked: every picture the case allows is written (pore_pressure, plastic_strain, probes; runout
# for the slope, terzaghi for the columns) as a PNG, and in SVG with its axis labels, units and
# colour-bar label as text; --frame picks a frame; exit 4 for a missing file, 2 for a file that is
# not a result, for a frame out of range and for an unknown option, each with a message naming it.
# Prints "PASS name" / "FAIL name: why". Runs in about 30 s.
#   bash tests/cli/plot_test.sh BUILD_DIR      (from the repository root)
set -u
cd "$(dirname "$0")/../.."
. tests/cli/lib.sh
cli_setup "${1:-build}"
plot="$build/poro-plot"

SHORT='c["time"]["end"] = 0.1; c["output"]["frame_interval"] = 0.025'
derive_case double tests/cases/terzaghi.json "$SHORT"
derive_case single tests/cases/terzaghi_single_point.json "$SHORT"
derive_case slope tests/cases/mc_slope_k1e-3_double_point.json 'c["time"]["end"] = 0.1; c["output"]["frame_interval"] = 0.05'
for kind in double single slope; do
	run_derived "$kind" "${kind}_run"
done

# png_files DIR NAME...: 0 when every DIR/NAME.png starts with the PNG signature
png_files() {
	local dir=$1 name
	shift
	for name in "$@"; do
		head -c 8 "$dir/$name.png" 2> /dev/null | od -An -tx1 | tr -d ' \n' | grep -qx 89504e470d0a1a0a || return 1
	done
}

for kind in double single; do
	"$plot" "$tmp/$kind/result.h5" > "$tmp/out" 2> "$tmp/err"
	rc=$?
	png_files "$tmp/$kind" pore_pressure plastic_strain probes terzaghi
	check "${kind}_point_column_pictures_written" $(( rc != 0 || $? != 0 )) \
		"exit $rc: $(head -c 300 "$tmp/err"); $(ls "$tmp/$kind")"
	[ ! -e "$tmp/$kind/runout.png" ]
	check "${kind}_point_column_has_no_runout_picture" $? "a rectangle body is not a slope"
done

mkdir -p "$tmp/slope_pictures"
"$plot" "$tmp/slope/result.h5" --out "$tmp/slope_pictures" > "$tmp/out" 2> "$tmp/err"
rc=$?
png_files "$tmp/slope_pictures" pore_pressure plastic_strain probes runout
check slope_pictures_written_into_out $(( rc != 0 || $? != 0 )) "exit $rc: $(head -c 300 "$tmp/err")"
[ "$(wc -l < "$tmp/out")" -eq 4 ] && ! ls -A "$tmp/slope_pictures" | grep -q '^\.'
check slope_one_line_per_file_no_scratch_left $? "$(cat "$tmp/out"); $(ls -A "$tmp/slope_pictures")"

mkdir -p "$tmp/svg"
"$plot" "$tmp/double/result.h5" --out "$tmp/svg" --format svg --frame 1 > /dev/null 2> "$tmp/err"
rc=$?
grep -q 'x (m)' "$tmp/svg/pore_pressure.svg" && grep -q 'pore pressure (kPa, compression +)' "$tmp/svg/pore_pressure.svg" &&
	grep -q 'at t = 0.025 s' "$tmp/svg/pore_pressure.svg" && grep -q 'p / q' "$tmp/svg/terzaghi.svg" &&
	grep -q 'Tv = ' "$tmp/svg/terzaghi.svg"
check svg_has_axes_units_colour_bar_and_chosen_frame $(( rc != 0 || $? != 0 )) "exit $rc: $(head -c 300 "$tmp/err")"

# bad input: exit status and a message naming what is wrong
expect_plot_refused() {   # NAME STATUS PATTERN ARGS...
	local name=$1 want=$2 pattern=$3 rc
	shift 3
	"$plot" "$@" > /dev/null 2> "$tmp/err"
	rc=$?
	grep -q -- "$pattern" "$tmp/err"
	check "$name" $(( rc != want || $? != 0 )) "exit $rc (want $want), stderr: $(head -c 300 "$tmp/err")"
}
expect_plot_refused missing_file_exit_4 4 "no such file" "$tmp/nothing.h5"
echo "not hdf5" > "$tmp/text.h5"
expect_plot_refused text_file_exit_2 2 "is not a result file" "$tmp/text.h5"
expect_plot_refused frame_out_of_range_exit_2 2 "has frames 0 to 4" "$tmp/double/result.h5" --frame 9
expect_plot_refused unknown_option_exit_2 2 "unrecognized arguments" "$tmp/double/result.h5" --colour red
"$plot" --help > /dev/null 2>&1
check help_exits_0 $? "--help failed"
