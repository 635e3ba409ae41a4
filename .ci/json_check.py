#!/usr/bin/env python3
"""Checks the JSON channels of MCAP logs as Foxglove's JSON-schema reader reads them.

For every channel with a `jsonschema` schema: the schema must be one the reader turns into
message definitions (`parseJsonSchema` of Foxglove Studio's MCAP support, the same in
Lichtblick: every object lists its `properties`; every field has one `type` among boolean,
string, number, integer, object and array; array items are scalars or objects), and every
message must give each field the schema declares a value of its type (a field may be
absent; `null` is not a value). Exits 1 on the first log with a problem, naming the topic,
the field and the problem.

    python3 .ci/json_check.py LOG.mcap [LOG.mcap ...]
"""

import json
import sys

from mcap.reader import make_reader

SCALARS = {"boolean", "string", "number", "integer"}


def schema_problems(schema, path):
    if schema.get("type") != "object":
        return [f'{path}: expected "type": "object"']
    props = schema.get("properties")
    if not isinstance(props, dict):
        return [f"{path}: an object without properties"]
    out = []
    for name, field in props.items():
        p = f"{path}.{name}"
        t = field.get("type")
        if t in SCALARS:
            continue
        if t == "object":
            out += schema_problems(field, p)
        elif t == "array":
            items = field.get("items", {})
            it = items.get("type")
            if it == "object":
                out += schema_problems(items, p)
            elif it not in SCALARS:
                out.append(f"{p}: unsupported array item type {it!r}")
        else:
            out.append(f"{p}: unsupported type {t!r}")
    return out


def value_problems(value, schema, path):
    t = schema.get("type")
    ok = {
        "boolean": lambda v: isinstance(v, bool),
        "string": lambda v: isinstance(v, str),
        "number": lambda v: isinstance(v, (int, float)) and not isinstance(v, bool),
        "integer": lambda v: isinstance(v, int) and not isinstance(v, bool),
        "object": lambda v: isinstance(v, dict),
        "array": lambda v: isinstance(v, list),
    }[t]
    if not ok(value):
        return [f"{path}: {json.dumps(value)[:60]} is not of type {t}"]
    out = []
    if t == "object":
        for name, v in value.items():
            if v is None:
                out.append(f"{path}.{name}: null (leave the field out instead)")
        for name, field in schema["properties"].items():
            if name in value and value[name] is not None:
                out += value_problems(value[name], field, f"{path}.{name}")
    elif t == "array":
        for i, v in enumerate(value):
            out += value_problems(v, schema["items"], f"{path}[{i}]")
    return out


def check(path):
    problems = []
    checked = {}
    with open(path, "rb") as f:
        reader = make_reader(f)
        for schema, channel, message in reader.iter_messages():
            if schema is None or schema.encoding != "jsonschema":
                continue
            s = json.loads(schema.data)
            if channel.topic not in checked:
                checked[channel.topic] = 0
                problems += [f"{channel.topic} schema: {p}" for p in schema_problems(s, schema.name)]
                if problems:
                    break
            checked[channel.topic] += 1
            value = json.loads(message.data)
            problems += [f"{channel.topic} at {message.log_time}: {p}" for p in value_problems(value, s, "")]
            if problems:
                break
    return problems, checked


def main():
    bad = 0
    for path in sys.argv[1:]:
        problems, checked = check(path)
        if problems:
            bad += 1
            print(f"{path}: {problems[0]}", file=sys.stderr)
        else:
            n = sum(checked.values())
            print(f"{path}: {n} JSON messages on {len(checked)} channels read as Foxglove reads them")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
