#!/usr/bin/env python3
"""Validates JSON documents against docs/cellmap.schema.json.

usage: schema_check.py SCHEMA FILE...   (each FILE holds one JSON document)

Debian's python3-jsonschema is not on the machines the tests run on, so this
implements the part of JSON Schema (2020-12) the schema uses: type, const,
enum, minimum, required, properties, additionalProperties, items, minItems,
maxItems, oneOf and local $ref. A keyword it does not know is an error, so
the schema cannot silently use more than is checked."""
import json
import sys

KNOWN = {"$schema", "$id", "$defs", "title", "description", "type", "const", "enum",
         "minimum", "required", "properties", "additionalProperties", "items",
         "minItems", "maxItems", "oneOf", "$ref"}
TYPES = {
    "object": lambda v: isinstance(v, dict),
    "array": lambda v: isinstance(v, list),
    "string": lambda v: isinstance(v, str),
    "boolean": lambda v: isinstance(v, bool),
    "null": lambda v: v is None,
    "integer": lambda v: isinstance(v, int) and not isinstance(v, bool),
    "number": lambda v: isinstance(v, (int, float)) and not isinstance(v, bool),
}


def errors(schema, value, root, path):
    """The problems of value against schema, as "path: problem" texts."""
    unknown = set(schema) - KNOWN
    if unknown:
        return [f"schema at {path} uses unsupported keywords {sorted(unknown)}"]
    if "$ref" in schema:
        node = root
        for part in schema["$ref"].lstrip("#/").split("/"):
            node = node[part]
        return errors(node, value, root, path)
    if "oneOf" in schema:
        matching = [s for s in schema["oneOf"] if not errors(s, value, root, path)]
        if len(matching) != 1:
            return [f"{path}: matches {len(matching)} of the oneOf alternatives, not 1"]
    found = []
    if "type" in schema:
        types = schema["type"] if isinstance(schema["type"], list) else [schema["type"]]
        if not any(TYPES[t](value) for t in types):
            return [f"{path}: {json.dumps(value)[:60]} is not of type {types}"]
    if "const" in schema and value != schema["const"]:
        found.append(f"{path}: {value!r} is not {schema['const']!r}")
    if "enum" in schema and value not in schema["enum"]:
        found.append(f"{path}: {value!r} is not one of {schema['enum']}")
    if "minimum" in schema and TYPES["number"](value) and value < schema["minimum"]:
        found.append(f"{path}: {value} is below {schema['minimum']}")
    if isinstance(value, dict):
        for key in schema.get("required", []):
            if key not in value:
                found.append(f"{path}: missing {key!r}")
        props = schema.get("properties", {})
        extra = schema.get("additionalProperties", True)
        for key, item in value.items():
            if key in props:
                found += errors(props[key], item, root, f"{path}.{key}")
            elif extra is False:
                found.append(f"{path}: unexpected {key!r}")
            elif isinstance(extra, dict):
                found += errors(extra, item, root, f"{path}.{key}")
    if isinstance(value, list):
        if len(value) < schema.get("minItems", 0) or len(value) > schema.get("maxItems", len(value)):
            found.append(f"{path}: {len(value)} items")
        if "items" in schema:
            for i, item in enumerate(value):
                found += errors(schema["items"], item, root, f"{path}[{i}]")
    return found


def main():
    schema = json.load(open(sys.argv[1]))
    bad = 0
    for name in sys.argv[2:]:
        try:
            doc = json.load(open(name))
        except ValueError as e:
            print(f"FAIL: {name} is not JSON: {e}")
            bad += 1
            continue
        problems = errors(schema, doc, schema, "$")
        if problems and "oneOf" in schema and isinstance(doc, dict):
            # say why against the alternative the document claims to be
            for alt in schema["oneOf"]:
                target = schema["$defs"][alt["$ref"].split("/")[-1]]
                shape = target.get("oneOf", [target])[0]  # a command with several shapes
                if shape["properties"]["command"].get("const") == doc.get("command"):
                    problems = errors(target, doc, schema, "$") or problems
        for p in problems[:10]:
            print(f"FAIL: {name}: {p}")
        bad += bool(problems)
    sys.exit(1 if bad else 0)


main()
