#!/usr/bin/env python3
"""Checks the dataset spec's JSON Schema (`xbandsim dataset schema`) with a real validator:
it is a valid draft 2020-12 schema, every example spec in datasets/ conforms, and specs with
an unknown field, a malformed law or an unknown library class do not.

Usage: check_schema.py SCHEMA.json SPEC.toml...   (exit status 1 on any failure)
"""
import json
import sys
import tomllib

import jsonschema


def main(schema_path, specs):
    schema = json.load(open(schema_path))
    jsonschema.Draft202012Validator.check_schema(schema)
    v = jsonschema.Draft202012Validator(schema)
    for path in specs:
        errors = [e.message for e in v.iter_errors(tomllib.load(open(path, "rb")))]
        assert not errors, (path, errors)
    bad = [
        {"dataset": {"frame": 2}},
        {"targets": {"count": {"uniform": [1]}}},
        {"targets": {"count": {"uniform": [0, 1], "normal": [0, 1]}}},
        {"targets": {"class": [{"library": "submarine"}]}},
        {"targets": {"class": [{"weight": 1}]}},
        {"vary": {"environment.sea_state": {"gamma": [1, 2]}}},
    ]
    for spec in bad:
        assert list(v.iter_errors(spec)), f"accepted {spec}"
    print(f"{schema_path}: valid; {len(specs)} example specs conform; {len(bad)} bad specs refused")


if __name__ == "__main__":
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    main(sys.argv[1], sys.argv[2:])
