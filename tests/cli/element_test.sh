#!/usr/bin/env bash
# element_test.sh - drives `poro-solve element` and `poro-solve validate` with the Mohr-Coulomb
# family: every element case in tests/cases/ runs end to end (exit 0, element.csv with its header
# row and one row per step; poro-plot draws it into element.svg, well-formed XML by python3's xml
# module with the three panels' axis labels and the case's title as text); invalid material
# parameters, in a simulation case (derived from tests/cases/terzaghi.json) and in an element case,
# are refused with exit 2 and the JSON pointer of the value. Prints "PASS name" / "FAIL name: why".
#   bash tests/cli/element_test.sh BUILD_DIR      (from the repository root)
set -u
cd "$(dirname "$0")/../.."
. tests/cli/lib.sh
cli_setup "${1:-build}"

# ---- every element case runs and writes its two files ------------------------------------------

for case in tests/cases/*.json; do
	grep -q '"poro-element/1"' "$case" || continue
	name=$(basename "$case" .json)
	out="$tmp/$name"
	"$solve" element "$case" --out "$out" > "$tmp/stdout" 2> "$tmp/err"
	rc=$?
	check "element_${name}_exits_0" "$rc" "exit $rc: $(head -c 300 "$tmp/err")"
	header=$(head -1 "$out/element.csv" 2>/dev/null)
	case "$header" in axial_strain,p,q,volumetric_strain*) ok=0 ;; *) ok=1 ;; esac
	check "element_${name}_csv_header" $ok "header '$header'"
	"$build/poro-plot" "$out/element.csv" --case "$case" --format svg > /dev/null 2> "$tmp/err"
	rc=$?
	check "element_${name}_poro_plot_exits_0" "$rc" "exit $rc: $(head -c 300 "$tmp/err")"
	python3 - "$case" "$out/element.csv" "$out/element.svg" <<'PY'
import csv, json, sys, xml.etree.ElementTree as ET
case = json.load(open(sys.argv[1]))
rows = list(csv.reader(open(sys.argv[2])))
assert len(rows) == case["steps"] + 2, "%d rows for %d steps" % (len(rows), case["steps"])
assert all(len(r) == len(rows[0]) for r in rows), "ragged rows"
assert abs(float(rows[-1][0]) - case["axial_strain"]) <= 1e-9 * abs(case["axial_strain"]), "final axial strain"
root = ET.parse(sys.argv[3]).getroot()
assert root.tag == "{http://www.w3.org/2000/svg}svg", root.tag
text = " ".join(t.text or "" for t in root.iter("{http://www.w3.org/2000/svg}text"))
for label in ("q against p", "q against axial strain", "volumetric strain", "p, mean effective stress (kPa)",
              case.get("title", "single element")):
    assert label in text, "no '%s' in the picture's text" % label
PY
	rc=$?
	check "element_${name}_csv_rows_and_svg_xml" $rc "python3 check failed"
done

# ---- invalid material parameters: validate exits 2 naming the pointer --------------------------

MOHR_COULOMB='{"model": "mohr_coulomb", "cohesion": 2e4, "friction_angle": 30, "dilation_angle": 0}'
derive() { derive_material "$1" "$MOHR_COULOMB" "$2"; }
bad() { expect_invalid "$@"; }

derive mohr_coulomb_valid 'm["strain"] = "small"; m["strength_reduction_factor"] = 2'
"$solve" validate "$tmp/mohr_coulomb_valid.json" > /dev/null 2> "$tmp/err"
rc=$?
check validate_mohr_coulomb_case_exits_0 $rc "exit $rc: $(head -c 300 "$tmp/err")"

derive friction_angle_95 'm["friction_angle"] = 95'
derive friction_angle_zero 'm["friction_angle"] = 0'
derive dilation_above_friction 'm["dilation_angle"] = 35'
derive dilation_negative 'm["dilation_angle"] = -2'
derive cohesion_missing 'del m["cohesion"]'
derive cohesion_negative 'm["cohesion"] = -5'
derive youngs_modulus_negative 'm["youngs_modulus"] = -1e7'
derive strain_unknown 'm["strain"] = "large"'
derive srf_zero 'm["strength_reduction_factor"] = 0'
derive tresca_key_on_mohr_coulomb 'm["peak_cohesion"] = 1e4'
derive tresca_residual_above_peak 'm.update({"model": "tresca_softening", "peak_cohesion": 6.4e3, "residual_cohesion": 7e3, "residual_plastic_strain": 0.75}); [m.pop(k) for k in ("cohesion", "friction_angle", "dilation_angle")]'
derive dilation_model_eta_negative 'm.update({"model": "mohr_coulomb_dilation", "initial_dilation_angle": -5, "critical_dilation_angle": 0, "dilation_evolution_parameter": -25}); m.pop("dilation_angle")'

bad friction_angle_95 /materials/0/friction_angle
bad friction_angle_zero /materials/0/friction_angle
bad dilation_above_friction /materials/0/dilation_angle
bad dilation_negative /materials/0/dilation_angle
bad cohesion_missing /materials/0/cohesion
bad cohesion_negative /materials/0/cohesion
bad youngs_modulus_negative /materials/0/youngs_modulus
bad strain_unknown /materials/0/strain
bad srf_zero /materials/0/strength_reduction_factor
bad tresca_key_on_mohr_coulomb /materials/0/peak_cohesion
bad tresca_residual_above_peak /materials/0/residual_cohesion
bad dilation_model_eta_negative /materials/0/dilation_evolution_parameter

# ---- an invalid element case: validate and element both exit 2 naming the pointer -------------

derive_element element_bad tests/cases/mohr_coulomb_drained.json 'c["material"]["friction_angle"] = 90; c["steps"] = 0'
bad element_friction_angle_90 /material/friction_angle "$tmp/element_bad.json"
expect_element_refused element_invalid_case "$tmp/element_bad.json" /material/friction_angle /steps
