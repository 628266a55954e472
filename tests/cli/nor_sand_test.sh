#!/usr/bin/env bash
# nor_sand_test.sh - Nor-Sand parameters through `poro-solve validate`: a simulation case derived
# from tests/cases/terzaghi.json with a nor_sand material (000 Table 6) is accepted, and each invalid
# parameter is refused with exit 2 and the JSON pointer of the value; an invalid element case too.
# (The Nor-Sand element cases themselves run in element_test.sh, which runs every element case.)
# Prints "PASS name" / "FAIL name: why".
#   bash tests/cli/nor_sand_test.sh BUILD_DIR      (from the repository root)
set -u
cd "$(dirname "$0")/../.."
. tests/cli/lib.sh
cli_setup "${1:-build}"

# 000 Table 6 (Hostun sand); the elastic constants of the base case are not Nor-Sand keys
HOSTUN='{"model": "nor_sand", "youngs_modulus": null, "poisson_ratio": null, "shear_modulus": 40e6,
 "swelling_index": 0.002, "compression_index": 0.02, "reference_specific_volume": 1.892,
 "critical_stress_ratio": 1.0, "yield_function_constant": 0.1, "plastic_potential_constant": 0.1,
 "hardening_coefficient": 100, "dilatancy_multiplier": -2.0, "initial_specific_volume": 1.7}'
derive() { derive_material "$1" "$HOSTUN" "$2"; }
bad() { expect_invalid "nor_sand_$1" "$2" "${3:-$tmp/$1.json}"; }

derive valid 'm.update({"strain": "small", "overconsolidation_ratio": 1.5, "critical_state_reference_pressure": 1e3, "initial_reference_pressure": 2e3, "dilatancy_cutoff_start": 1.0, "dilatancy_cutoff_end": 1.5, "gas_volume_ratio": 1.6, "initial_yield_surface": "through_stress"})'
"$solve" validate "$tmp/valid.json" > /dev/null 2> "$tmp/err"
rc=$?
check validate_nor_sand_case_exits_0 $rc "exit $rc: $(head -c 300 "$tmp/err")"

derive N_one 'm["yield_function_constant"] = 1'
derive N_negative 'm["yield_function_constant"] = -0.1'
derive Nbar_above_one 'm["plastic_potential_constant"] = 1.2'
derive shear_modulus_negative 'm["shear_modulus"] = -40e6'
derive swelling_index_zero 'm["swelling_index"] = 0'
derive compression_index_missing 'del m["compression_index"]'
derive critical_stress_ratio_missing 'del m["critical_stress_ratio"]'
derive alpha_positive 'm["dilatancy_multiplier"] = 2'
derive hardening_negative 'm["hardening_coefficient"] = -1'
derive specific_volume_below_one 'm["initial_specific_volume"] = 0.9'
derive reference_specific_volume_string 'm["reference_specific_volume"] = "1.892"'
derive ocr_below_one 'm["overconsolidation_ratio"] = 0.8'
derive cutoff_end_before_start 'm.update({"dilatancy_cutoff_start": 1.5, "dilatancy_cutoff_end": 1.0})'
derive gas_ratio_one 'm["gas_volume_ratio"] = 1'
derive yield_surface_unknown 'm["initial_yield_surface"] = "outside"'
derive youngs_modulus_on_nor_sand 'm["youngs_modulus"] = 1e7'
derive nor_sand_key_on_mohr_coulomb 'm.clear(); m.update({"name": "soil", "density": 2650, "model": "mohr_coulomb", "youngs_modulus": 1e7, "poisson_ratio": 0.3, "cohesion": 1e4, "friction_angle": 30, "dilation_angle": 0, "shear_modulus": 4e6})'

bad N_one /materials/0/yield_function_constant
bad N_negative /materials/0/yield_function_constant
bad Nbar_above_one /materials/0/plastic_potential_constant
bad shear_modulus_negative /materials/0/shear_modulus
bad swelling_index_zero /materials/0/swelling_index
bad compression_index_missing /materials/0/compression_index
bad critical_stress_ratio_missing /materials/0/critical_stress_ratio
bad alpha_positive /materials/0/dilatancy_multiplier
bad hardening_negative /materials/0/hardening_coefficient
bad specific_volume_below_one /materials/0/initial_specific_volume
bad reference_specific_volume_string /materials/0/reference_specific_volume
bad ocr_below_one /materials/0/overconsolidation_ratio
bad cutoff_end_before_start /materials/0/dilatancy_cutoff_end
bad gas_ratio_one /materials/0/gas_volume_ratio
bad yield_surface_unknown /materials/0/initial_yield_surface
bad youngs_modulus_on_nor_sand /materials/0/youngs_modulus
bad nor_sand_key_on_mohr_coulomb /materials/0/shear_modulus

# ---- an invalid Nor-Sand element case: validate and element both exit 2 naming the pointer ------

derive_element element_bad tests/cases/norsand_undrained_p100.json \
	'c["material"]["yield_function_constant"] = 1.0; del c["material"]["shear_modulus"]'
bad element_N_one /material/yield_function_constant "$tmp/element_bad.json"
expect_element_refused element_nor_sand_invalid_case "$tmp/element_bad.json" /material/yield_function_constant \
	/material/shear_modulus
