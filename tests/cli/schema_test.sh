#!/usr/bin/env bash
# schema_test.sh - the JSON schemas editors use (schemas/case.schema.json, element.schema.json)
# against the solver's own loader (`poro-solve validate`): both schemas are valid 2020-12 schemas,
# every file in tests/cases/ is accepted by its schema and by the solver, and mutations of those
# files (wrong type, out of range, unknown key, a key of another model or kind, a missing
# required key, and valid variants: inclusive bounds, optional keys removed, "$schema", a title
# of the most characters), one drawn with a fixed seed from each part of the case and kind of
# mutation, get the same verdict from both, a refusal naming the mutated object on both sides; and
# one hand-made mutation for each rule between keys that both state (a dry body with the
# consistent projection, a plate without its plate object, ...).
# tests/cli/schema_agreement.py does the work and says how the mutations are made; every
# disagreement is a FAIL naming the mutation and the case it came from.
# Debian's python3 with python3-jsonschema (deploy/deps.sh). Runs in about 10 s.
#   bash tests/cli/schema_test.sh BUILD_DIR      (from the repository root)
set -u
cd "$(dirname "$0")/../.."
. tests/cli/lib.sh
cli_setup "${1:-build}"

SCHEMA_PYTHON=/usr/bin/python3   # Debian's, where python3-jsonschema installs
"$SCHEMA_PYTHON" -c 'import jsonschema' 2> "$tmp/err"
check schema_test_has_python3_jsonschema $? "$(cat "$tmp/err") (deploy/deps.sh installs python3-jsonschema)"
"$SCHEMA_PYTHON" tests/cli/schema_agreement.py "$solve" "$tmp"
