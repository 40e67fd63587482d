#!/usr/bin/env python3
"""Reads an MCAP recording of `mrt sim --record` with the `mcap` package from PyPI and checks
every message against its channel's JSON schema with `jsonschema`.

    pip install mcap jsonschema
    python3 examples/python/check_recording.py match.mcap

Prints one JSON line, {"messages": N, "topics": T, "invalid": 0, "truth": K}, and exits 1 when
a message does not decode or does not match its schema (the first few are printed to
stderr), 3 when a package is missing.
"""
import json
import sys

try:
    import jsonschema
    from mcap.reader import make_reader
except ImportError as e:  # the caller may skip the check
    print(f"missing Python package: {e.name} (pip install mcap jsonschema)", file=sys.stderr)
    sys.exit(3)


def main(path):
    validators = {}
    messages = invalid = truth = 0
    topics = set()
    with open(path, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages():
            messages += 1
            topics.add(channel.topic)
            truth += channel.topic == "/truth"
            if schema is None or schema.encoding != "jsonschema" or channel.message_encoding != "json":
                invalid += 1
                continue
            v = validators.get(schema.id)
            if v is None:
                s = json.loads(schema.data)
                v = jsonschema.validators.validator_for(s)(s)
                validators[schema.id] = v
            try:
                v.validate(json.loads(message.data))
            except (ValueError, jsonschema.ValidationError) as e:
                invalid += 1
                if invalid <= 3:
                    print(f"{channel.topic} at {message.log_time}: {e}", file=sys.stderr)
    print(json.dumps({"messages": messages, "topics": len(topics), "invalid": invalid, "truth": truth}))
    return 1 if invalid else 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print("usage: check_recording.py FILE.mcap", file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
