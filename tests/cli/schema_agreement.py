#!/usr/bin/python3
"""schema_agreement.py - the JSON schemas and the solver's loader must agree on every case.

The case files are described twice: by schemas/case.schema.json and schemas/element.schema.json
(what editors validate and complete against, JSON Schema 2020-12) and by the solver's loaders
(solver/case/, solver/material/element_case.c). This program checks that both say the same:

 1. both schemas are valid 2020-12 schemas;
 2. every file in tests/cases/ is accepted by its schema (chosen by its "schema" key) and by
    `poro-solve validate`;
 3. a differential test: mutations of the shipped cases, each meant to be refused (a value of the
    wrong type; a value just out of its range, an exclusive bound itself or an inclusive bound
    moved past; an unknown key; a key of another model or kind; a missing required key) or to be
    accepted (a value on an inclusive bound, an optional key removed, a "$schema" added, a title of
    the most characters), must get that verdict from both the schema and the solver. Every object
    of every shipped case is a place to mutate, and what may be mutated there (its keys, their
    types and bounds, which keys are required, which belong to another model) is read from the
    schema; so a range or a required key that the schema states differently from the solver shows
    as a disagreement, whichever side is wrong. The candidates are grouped by the part of the case
    (formulation, grid, materials of each model, bodies, loads, ...) and the kind of mutation, and
    one candidate of each group is drawn with a fixed seed: a few dozen mutations, the same on
    every run. Besides them, one mutation for each rule between keys that both state (RULES: a
    dry body with the consistent projection, a plate with it, cavitation with the weak free
    surface, ...), made by hand since a draw of single-key mutations rarely meets one.

Each check prints "PASS name" or "FAIL name: why" (tests/run.sh counts them); a disagreement
names the mutation, the file it came from and what each side said.

Uses Debian's python3-jsonschema (4.10 on Debian 12; deploy/deps.sh); a newer jsonschema with the
referencing library works too.
  /usr/bin/python3 tests/cli/schema_agreement.py BUILD_DIR/poro-solve TMP_DIR [--all]
(from the repository root; --all tries every candidate instead of one from each group)
"""
import copy
import glob
import json
import os
import random
import subprocess
import sys

from jsonschema import Draft202012Validator

SEED = 2385
CASES = "tests/cases"
SCHEMAS = {"poro-case/1": "schemas/case.schema.json", "poro-element/1": "schemas/element.schema.json"}


def load_schemas():
    docs = {}
    for path in SCHEMAS.values():
        with open(path) as f:
            doc = json.load(f)
        docs[doc["$id"]] = doc
    return docs


def validator_factory(docs):
    """Validators that resolve the schemas' references to each other by their $id."""
    try:   # jsonschema >= 4.18
        from referencing import Registry, Resource
        registry = Registry().with_resources((i, Resource.from_contents(d)) for i, d in docs.items())
        return lambda schema: Draft202012Validator(schema, registry=registry)
    except ImportError:   # Debian 12's jsonschema 4.10
        from jsonschema import RefResolver
        return lambda schema: Draft202012Validator(
            schema, resolver=RefResolver.from_schema(schema, store=dict(docs)))


class Schema:
    """The schemas, with the little reading the mutations need: the effective properties and
    required keys of an object of the document, following $ref, allOf and the branches of if/then
    and oneOf that apply to the object."""

    def __init__(self):
        self.docs = load_schemas()
        self.make = validator_factory(self.docs)
        self.validators = {v: self.make(self.docs[os.path.basename(p)]) for v, p in SCHEMAS.items()}

    def resolve(self, ref, doc):
        """The schema a $ref names, and the document it lies in."""
        where, _, pointer = ref.partition("#")
        if where:
            doc = self.docs[where]
        node = doc
        for token in [t for t in pointer.split("/") if t]:
            node = node[token.replace("~1", "/").replace("~0", "~")]
        return node, doc

    def deref(self, node, doc):
        """A node that only refers to another ($ref with a description or a default) as the node it
        refers to, its own keywords kept; objects that add properties to a $ref stay as they are
        (object_schema follows their $ref)."""
        while "$ref" in node and "properties" not in node:
            target, doc = self.resolve(node["$ref"], doc)
            node = dict(target, **{k: v for k, v in node.items() if k != "$ref"})
        return node, doc

    def applies(self, sub, instance):
        return self.make(sub).is_valid(instance)

    def object_schema(self, node, doc, instance, props=None, required=None):
        """Collects properties {key: [(schema, doc), ...]} and the required keys for the object
        instance: a key may be constrained in several places (a branch adds bounds)."""
        props = {} if props is None else props
        required = set() if required is None else required
        node, doc = self.deref(node, doc)
        if "$ref" in node:
            sub, sub_doc = self.resolve(node["$ref"], doc)
            self.object_schema(sub, sub_doc, instance, props, required)
        for k, v in node.get("properties", {}).items():
            props.setdefault(k, []).append((v, doc))
        required.update(node.get("required", []))
        for item in node.get("allOf", []):
            if "if" in item:
                branch = item.get("then") if self.applies(item["if"], instance) else item.get("else")
                if branch:
                    self.object_schema(branch, doc, instance, props, required)
            else:
                self.object_schema(item, doc, instance, props, required)
        for item in node.get("oneOf", []):
            kind = item.get("properties", {}).get("kind", {}).get("const")
            if kind is not None and instance.get("kind") == kind:
                self.object_schema(item, doc, instance, props, required)
            elif kind is None and set(item) == {"required"} and set(item["required"]) <= set(instance):
                required.update(item["required"])   # the alternative present (a body's region)
        return props, required

    def branches(self, node, doc):
        """The alternatives of a discriminated object: [(label, {key: (schema, doc)})] of
        material_model's models or of a oneOf by kind; [] for other objects."""
        node, doc = self.deref(node, doc)
        if "$ref" in node:
            return self.branches(*self.resolve(node["$ref"], doc))
        out = []
        for item in node.get("allOf", []):
            model = item.get("if", {}).get("properties", {}).get("model", {}).get("const")
            if model:
                sub, sub_doc = self.resolve(item["then"]["$ref"], doc)
                out.append((model, {k: (v, sub_doc) for k, v in sub["properties"].items()}))
        for item in node.get("oneOf", []):
            kind = item.get("properties", {}).get("kind", {}).get("const")
            if kind:
                out.append((kind, {k: (v, doc) for k, v in item["properties"].items()}))
        return out

    def verdict(self, document):
        """(accepted, [error pointers], first message)."""
        v = self.validators.get(document.get("schema"), self.validators["poro-case/1"])
        errors = sorted(v.iter_errors(document), key=lambda e: list(e.path))
        if not errors:
            return True, [], ""
        pointers = []

        def collect(errs):   # with the errors inside oneOf's alternatives, which name the place
            for e in errs:
                pointers.append(pointer_of(e.absolute_path))
                collect(e.context or [])
        collect(errors)
        e = errors[0]
        return False, pointers, pointer_of(e.path) + ": " + e.message[:200]


def pointer_of(path):
    return "".join("/" + str(p).replace("~", "~0").replace("/", "~1") for p in path)


def objects(document, schema):
    """Every object of the document with its path and its schema node: (path, object, node, doc)."""
    root_doc = schema.docs[os.path.basename(SCHEMAS[document["schema"]])]
    out = []

    def walk(value, path, node, doc):
        node, doc = schema.deref(node, doc)
        if isinstance(value, dict):
            out.append((path, value, node, doc))
            props, _ = schema.object_schema(node, doc, value)
            for k, v in value.items():
                if k in props:
                    walk(v, path + [k], *props[k][0])
        elif isinstance(value, list) and "items" in node and isinstance(node["items"], dict):
            for i, v in enumerate(value):
                walk(v, path + [i], node["items"], doc)

    walk(document, [], root_doc, root_doc)
    return out


def part_label(document, path, obj):
    """The part of the case a mutation belongs to: the path without list indices, and the model
    of a material."""
    words = [str(p) for p in path if not isinstance(p, int)]
    label = ".".join(words) if words else "top"
    if document["schema"] == "poro-element/1":
        label = "element." + label
    if "model" in obj and isinstance(obj["model"], str):
        label += "[" + obj["model"] + "]"
    return label


def wrong_type(value):
    if isinstance(value, bool):
        return "true"
    if isinstance(value, (int, float)):
        return str(value)
    if isinstance(value, str):
        return 7
    if isinstance(value, list):
        return {"x": value}
    return [value]


def sample_value(schema, node, doc):
    """A value the schema accepts for a key (for keys added from another model)."""
    node, doc = schema.deref(node, doc)
    if "enum" in node:
        return node["enum"][0]
    if "const" in node:
        return node["const"]
    if node.get("type") in ("number", "integer"):
        lo = node.get("minimum", node.get("exclusiveMinimum"))
        hi = node.get("maximum", node.get("exclusiveMaximum"))
        if lo is not None and hi is not None:
            return (lo + hi) / 2
        if lo is not None:
            return lo + 1.5
        if hi is not None:
            return hi - 1.5
        return 2.5
    if node.get("type") == "string":
        return "x"
    if node.get("type") == "boolean":
        return True
    if node.get("type") == "array":
        return [0.25, 0.25]
    return 1


def merged(schema, nodes):
    """One schema node for a key constrained in several places: the union of their keywords, the
    tightest of their numeric bounds (an exclusive bound wins over an inclusive one at the same
    value)."""
    out, doc = {}, None
    lo = hi = None   # (value, exclusive)
    for node, node_doc in nodes:
        node, node_doc = schema.deref(node, node_doc)
        doc = doc or node_doc
        for k, v in node.items():
            if k in ("minimum", "exclusiveMinimum"):
                b = (v, k == "exclusiveMinimum")
                lo = b if lo is None or b > lo else lo
            elif k in ("maximum", "exclusiveMaximum"):
                b = (v, k == "exclusiveMaximum")
                hi = b if hi is None or (b[0], not b[1]) < (hi[0], not hi[1]) else hi
            else:
                out.setdefault(k, v)
    if lo:
        out["exclusiveMinimum" if lo[1] else "minimum"] = lo[0]
    if hi:
        out["exclusiveMaximum" if hi[1] else "maximum"] = hi[0]
    return out, doc


def range_mutations(schema, nodes, key, value):
    """(new value, meant to be valid, what) for a value at the edges of its range."""
    node, doc = merged(schema, nodes)
    out = []
    number = isinstance(value, (int, float)) and not isinstance(value, bool)
    if node.get("type") in ("number", "integer", None) and number:
        for bound, exclusive, sign in (("exclusiveMinimum", True, -1), ("minimum", False, -1),
                                      ("exclusiveMaximum", True, 1), ("maximum", False, 1)):
            if bound not in node:
                continue
            b = node[bound]
            if exclusive:
                out.append((b, False, "%s on its exclusive bound %s" % (key, bound)))
            else:
                out.append((b, True, "%s on its inclusive bound %s" % (key, bound)))
                past = b + sign * max(abs(b) * 1e-6, 1e-6)
                out.append((past, False, "%s just past its %s" % (key, bound)))
        if node.get("type") == "integer":
            out.append((value + 0.5, False, "%s not an integer" % key))
        if "const" in node.get("not", {}):
            out.append((node["not"]["const"], False, "%s on the value it may not take" % key))
    if "enum" in node and isinstance(value, str):
        out.append(("no_such_" + key, False, "%s not one of its choices" % key))
    if "const" in node and isinstance(node["const"], str):
        out.append((node["const"] + "x", False, "%s not its one allowed value" % key))
    patterned = "pattern" in node or "pattern" in node.get("not", {})
    if node.get("type") == "string" and "maxLength" in node and not patterned:
        n = node["maxLength"]
        out.append(("\u00e9" * n, True, "%s of %d accented characters, its maxLength" % (key, n)))
        out.append(("\u00e9" * (n + 1), False, "%s of %d accented characters, past its maxLength" % (key, n + 1)))
    if patterned and isinstance(value, str):
        out.append((value + " x", False, "%s with a space" % key))
        out.append((value + "\n", False, "%s ending in a newline" % key))
    if node.get("type") == "array" and isinstance(value, list):
        if "minItems" in node:
            out.append((value[: node["minItems"] - 1], False, "%s with too few items" % key))
        items, _ = schema.deref(node.get("items", {}), doc)
        if "exclusiveMinimum" in items and value and isinstance(value[0], (int, float)):
            out.append(([items["exclusiveMinimum"]] + value[1:], False, "%s item on its exclusive bound" % key))
    return out


class Mutation:
    def __init__(self, group, what, document, valid, file, path):
        self.group, self.what, self.document, self.valid, self.file = group, what, document, valid, file
        self.pointer = pointer_of(path)   # the mutated object: a refusal must name it or a key in it


def candidates(file, document, schema):
    """Every mutation of the document (Mutation)."""
    out = []
    element = document["schema"] == "poro-element/1"

    def add(group, what, path, change, valid):
        d = copy.deepcopy(document)
        target = d
        for p in path:
            target = target[p]
        change(target)
        out.append(Mutation(group, "%s: %s" % (pointer_of(path) or "/", what), d, valid, file, path))

    for path, obj, node, doc in objects(document, schema):
        label = part_label(document, path, obj)
        props, required = schema.object_schema(node, doc, obj)
        for key, value in obj.items():
            add((label, "wrong_type"), "%s = %r, wrong type" % (key, wrong_type(value)), path,
                lambda o, k=key, v=wrong_type(value): o.__setitem__(k, v), False)
            for new, valid, what in range_mutations(schema, props.get(key, []), key, value):
                add((label, "at_bound" if valid else "out_of_range"), "%s = %r" % (what, new), path,
                    lambda o, k=key, v=new: o.__setitem__(k, v), valid)
            if key in required:
                add((label, "missing_required"), "%s removed (required)" % key, path,
                    lambda o, k=key: o.pop(k), False)
            else:
                add((label, "optional_removed"), "%s removed (optional)" % key, path,
                    lambda o, k=key: o.pop(k), True)
        for key in ("colour", (sorted(obj)[0] + "s") if obj else "x"):
            add((label, "unknown_key"), "unknown key %s added" % key, path,
                lambda o, k=key: o.__setitem__(k, 1), False)
        for branch, branch_props in schema.branches(node, doc):
            for key, (sub, sub_doc) in branch_props.items():
                if key in props:
                    continue
                value = sample_value(schema, sub, sub_doc)
                add((label, "other_model_key"), "%s = %r of %s added" % (key, value, branch), path,
                    lambda o, k=key, v=value: o.__setitem__(k, v), False)
    location = "../../" + SCHEMAS[document["schema"]]
    add(("element.top" if element else "top", "schema_location"), "$schema = %r added" % location, [],
        lambda o: o.__setitem__("$schema", location), True)
    return out


def set_at(path, value):
    """An edit that sets the value at path (a list of keys), or removes it when value is REMOVE."""
    def change(d):
        for p in path[:-1]:
            d = d[p]
        if value is REMOVE:
            d.pop(path[-1])
        else:
            d[path[-1]] = value
    return change


REMOVE = object()

# The rules between keys that the schema states (its if/then and dependentRequired) and the solver
# checks: (case file, what, edits, meant to be valid, the object a refusal names: the whole case
# where the two sides may name different keys of the rule, e.g. the body or the formulation).
RULES = [
    ("dry_embankment.json", "a dry body with the consistent projection",
     [set_at(["formulation", "pressure_projection"], "consistent")], False, []),
    ("dry_embankment.json", "a dry body with the Laplacian named",
     [set_at(["formulation", "pressure_projection"], "laplacian")], True, []),
    ("mandel.json", "a plate with the consistent projection",
     [set_at(["formulation", "pressure_projection"], "consistent")], False, []),
    ("mandel.json", "a plate face without its plate object",
     [set_at(["boundaries", "top", "plate"], REMOVE)], False, ["boundaries", "top"]),
    ("mandel.json", "a fixed face beside the plate",
     [set_at(["boundaries", "left", "soil"], "fixed")], False, ["boundaries"]),
    ("cavitation_column.json", "cavitation with the weak free surface",
     [set_at(["formulation", "pressure_projection"], "consistent"), set_at(["formulation", "free_surface"], "weak")],
     False, []),
    ("cavitation_column.json", "a cavitated bulk modulus without a cavitation pressure",
     [set_at(["fluid", "cavitated_bulk_modulus"], 1.5e6), set_at(["fluid", "cavitation_pressure"], REMOVE)],
     False, ["fluid"]),
    ("landslide_dense_double_point.json", "the elastic loading without a gravity ramp",
     [set_at(["gravity", "ramp_time"], REMOVE)], False, ["gravity"]),
    ("terzaghi.json", "APIC with a FLIP fraction",
     [set_at(["formulation", "velocity_update"], "apic"), set_at(["formulation", "flip_fraction"], 0.75)],
     False, ["formulation"]),
    ("terzaghi.json", "the second-difference stabilisation without the consistent projection",
     [set_at(["formulation", "pressure_stabilisation"], "second_difference")], False, ["formulation"]),
]


def rule_mutations():
    out = []
    for file, what, edits, valid, path in RULES:
        document = json.load(open(os.path.join(CASES, file)))
        for edit in edits:
            edit(document)
        out.append(Mutation(("rules", what.replace(" ", "_")), "%s (%s)" % (what, pointer_of(path) or "/"),
                            document, valid, file, path))
    return out


def solver_verdict(solve, path):
    """(accepted or None when it failed otherwise, [pointers of its problem lines], first line)."""
    r = subprocess.run([solve, "validate", path], capture_output=True, text=True)
    lines = [l for l in r.stderr.strip().splitlines() if not l.startswith("poro-solve: ")]
    if r.returncode not in (0, 2):
        return None, [], "exit %d: %s" % (r.returncode, r.stderr.strip()[:300])
    return r.returncode == 0, [l.split(": ", 1)[0] for l in lines], lines[0][:300] if lines else ""


def names(pointers, pointer):
    """One of the problems lies in the mutated object ("/" is the whole document)."""
    return any(p == pointer or p.startswith(pointer + "/") or pointer == "" for p in pointers)


def check(name, ok, why):
    print(("PASS %s" % name) if ok else ("FAIL %s: %s" % (name, why)))
    sys.stdout.flush()
    return ok


def verdict_word(accepted):
    return "fails" if accepted is None else "accepts" if accepted else "refuses"


def main():
    solve, tmp = sys.argv[1], sys.argv[2]
    schema = Schema()
    for path in SCHEMAS.values():
        errors = list(Draft202012Validator(Draft202012Validator.META_SCHEMA).iter_errors(json.load(open(path))))
        check("schema_%s_is_a_2020_12_schema" % os.path.basename(path).split(".")[0], not errors,
              "; ".join(e.message for e in errors[:3]))
    files = sorted(glob.glob(os.path.join(CASES, "*.json")))
    pool = []
    for file in files:
        document = json.load(open(file))
        name = os.path.basename(file)[:-5]
        ok_schema, _, why_schema = schema.verdict(document)
        ok_solver, _, why_solver = solver_verdict(solve, file)
        check("shipped_%s_valid_for_schema_and_solver" % name, ok_schema and ok_solver,
              "schema %s (%s), solver %s (%s)" % (verdict_word(ok_schema), why_schema,
                                                 verdict_word(ok_solver), why_solver))
        pool += candidates(os.path.basename(file), document, schema)
    groups = {}
    for m in pool:
        groups.setdefault(m.group, []).append(m)
    rng = random.Random(SEED)
    chosen = [rng.choice(groups[g]) for g in sorted(groups)]
    if "--all" in sys.argv:   # every candidate, not one a group: minutes, for changes to the schemas
        chosen = pool
    chosen += rule_mutations()
    print("INFO schema_agreement: %d mutations drawn (seed %d), one from each of %d groups (part of the case, "
          "kind of mutation) of %d candidates from %d files" % (len(chosen), SEED, len(groups), len(pool), len(files)))
    judged_otherwise = 0
    for i, m in enumerate(chosen):
        path = os.path.join(tmp, "mutation_%03d.json" % i)
        with open(path, "w") as f:
            json.dump(m.document, f, ensure_ascii=False)
        ok_schema, schema_pointers, why_schema = schema.verdict(m.document)
        ok_solver, solver_pointers, why_solver = solver_verdict(solve, path)
        name = "schema_agreement_%s_%s" % (m.group[0].replace("[", "_").replace("]", ""), m.group[1])
        ok = ok_schema == m.valid and ok_solver == m.valid
        if ok and not m.valid:   # each refuses it for the mutation, not for something else
            ok = names(schema_pointers, m.pointer) and names(solver_pointers, m.pointer)
        ok = check(name, ok, "%s %s (%s): schema %s%s, solver %s%s" % (
            m.file, m.what, "a valid variant" if m.valid else "meant to be refused",
            verdict_word(ok_schema), " (%s)" % why_schema if why_schema else "",
            verdict_word(ok_solver), " (%s)" % why_solver if why_solver else ""))
        judged_otherwise += not ok
    print("INFO schema_agreement: %d of %d mutations judged otherwise than meant" % (judged_otherwise, len(chosen)))


if __name__ == "__main__":
    main()
