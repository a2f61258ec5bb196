#!/usr/bin/env python3
"""Validates every graph and variant under graphs/ against the JSON Schema `vitrine schema` generates, with an
independent validator (Debian's python3-jsonschema, Draft 2020-12), and checks that the schema catches what the
renderer's own validator rejects.

usage: check_graph_schema.py VITRINE SOURCE_DIR WORK_DIR

Checks:
  1. graphs/vitrine-graph.schema.json is what `vitrine schema` writes now (not stale: regenerate it with
     `vitrine schema --out graphs/vitrine-graph.schema.json` after adding or changing a node type);
  2. it is a valid Draft 2020-12 schema;
  3. every graph file under graphs/ names it in "$schema" (as a path relative to the file) and validates;
  4. a handful of broken copies (wrong param type, value out of range, unknown param, unknown node type, missing
     required input, bad port reference, unknown top-level key) are flagged at the right JSON pointer, and the
     renderer (`vitrine validate`) rejects each of them too, so schema and renderer agree.
"""
import copy
import json
import os
import subprocess
import sys

try:
    import jsonschema
except ImportError:
    sys.exit("check_graph_schema: needs Debian's python3-jsonschema (tools/install-deps.sh installs it) "
             "and /usr/bin/python3")

vitrine, source, work = sys.argv[1:4]
graphs = os.path.join(source, "graphs")
schema_path = os.path.join(graphs, "vitrine-graph.schema.json")
failures = []


def fail(msg):
    failures.append(msg)
    print("FAIL:", msg)


generated = subprocess.run([vitrine, "schema"], check=True, capture_output=True, text=True).stdout
with open(schema_path) as f:
    committed = f.read()
if json.loads(generated) != json.loads(committed):
    fail(f"{schema_path} is stale: run `vitrine schema --out graphs/vitrine-graph.schema.json`")
schema = json.loads(generated)
jsonschema.Draft202012Validator.check_schema(schema)
validator = jsonschema.Draft202012Validator(schema)


def errors(doc):
    return sorted(validator.iter_errors(doc), key=lambda e: list(e.absolute_path))


count = 0
for root, _, files in os.walk(graphs):
    for name in sorted(files):
        # *.sweep.json: `vitrine sweep` files (graphs/sweeps/), not graphs; tests/unit/sweep checks them. *.regions.json:
        # `compare --regions` files (tests/unit/compare checks them).
        if not name.endswith(".json") or name.endswith(".schema.json") or name.endswith(".sweep.json") or name.endswith(".regions.json"):
            continue
        path = os.path.join(root, name)
        rel = os.path.relpath(path, source)
        with open(path) as f:
            doc = json.load(f)
        count += 1
        ref = doc.get("$schema")
        if ref is None:
            fail(f"{rel}: no \"$schema\" key")
        elif os.path.normpath(os.path.join(root, ref)) != os.path.normpath(schema_path):
            fail(f"{rel}: \"$schema\" is {ref!r}, which does not point at graphs/vitrine-graph.schema.json")
        for e in errors(doc):
            fail(f"{rel}: {e.json_path}: {e.message[:200]}")
print(f"{count} graph files validated against the schema")
if count < 3:
    fail("found fewer than 3 graph files: wrong SOURCE_DIR?")

# Broken copies of a plain graph and of a variant: the schema must flag each at the given pointer, and the renderer
# must reject the same file.
with open(os.path.join(graphs, "fxaa_zoneplate.json")) as f:
    base = json.load(f)


def broken(edit):
    doc = copy.deepcopy(base)
    edit(doc)
    return doc


cases = [
    ("wrong param type", broken(lambda d: d["nodes"]["fxaa"].setdefault("params", {}).update(subpix="high")),
     "$.nodes.fxaa.params.subpix"),
    ("param out of range", broken(lambda d: d["nodes"]["fxaa"].setdefault("params", {}).update(subpix=2)),
     "$.nodes.fxaa.params.subpix"),
    ("unknown param", broken(lambda d: d["nodes"]["fxaa"].setdefault("params", {}).update(sharpness=1)),
     "$.nodes.fxaa.params"),
    ("enum value", broken(lambda d: d["nodes"]["tonemap"]["params"].update(operator="filmic-ish")),
     "$.nodes.tonemap.params.operator"),
    ("unknown node type", broken(lambda d: d["nodes"]["fxaa"].update(type="aa.fxaaa")), "$.nodes.fxaa.type"),
    ("missing required input", broken(lambda d: d["nodes"]["fxaa"].pop("in")), "$.nodes.fxaa"),
    ("bad port reference", broken(lambda d: d["nodes"]["fxaa"]["in"].update(color="pattern")),
     "$.nodes.fxaa.in.color"),
    ("unknown top-level key", broken(lambda d: d.update(node={})), "$"),
    ("bad node id", broken(lambda d: d["nodes"].update({"2x": {"type": "aa.fxaa", "in": {"color": "pattern.color"}}})),
     "$.nodes"),
]
os.makedirs(work, exist_ok=True)
for what, doc, pointer in cases:
    errs = errors(doc)
    if not any(e.json_path == pointer for e in errs):
        fail(f"{what}: the schema did not flag {pointer} (errors: {[e.json_path for e in errs]})")
    path = os.path.join(work, "broken.json")
    with open(path, "w") as f:
        json.dump(doc, f)
    r = subprocess.run([vitrine, "validate", path], capture_output=True, text=True)
    if r.returncode != 1:
        fail(f"{what}: `vitrine validate` exited {r.returncode} (expected 1: the renderer rejects it too)")

# A variant: null deletes a node, a partial node needs no type, but a wrong param type is still flagged.
variant = {"$schema": "../vitrine-graph.schema.json", "extends": "../fxaa_zoneplate.json",
           "nodes": {"fxaa": None, "tonemap": {"in": {"color": "pattern.color"}}}}
for e in errors(variant):
    fail(f"valid variant flagged: {e.json_path}: {e.message[:200]}")
bad_variant = copy.deepcopy(variant)
bad_variant["nodes"]["tonemap"] = {"type": "post.tonemap", "params": {"operator": 3}}
if not any(e.json_path == "$.nodes.tonemap.params.operator" for e in errors(bad_variant)):
    fail("variant with a wrong param type not flagged at $.nodes.tonemap.params.operator")

if failures:
    sys.exit(f"{len(failures)} schema check(s) failed")
print("schema checks passed")
