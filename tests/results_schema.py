"""The JSON Schema of ``results.json``: inferred from a report, then kept as the contract.

Regenerate (after a deliberate change of the results' structure)::

    python tests/results_schema.py reports/paper/results.json > ptoverify/report/results.schema.json

The inferred schema requires every key the report wrote, forbids unknown keys,
and fixes each leaf's JSON type; numbers may be ``null`` (undefined: never
settles, no solution), as the sections expect.  Lists of objects take the
union of their items' keys, required where every item has them.
"""

from __future__ import annotations

import json
import sys
from typing import Any

#: Stages ``report --skip`` can leave out (their key is then null).
OPTIONAL_STAGES = ("robust", "tuning", "charts")
SCALAR = {bool: "boolean", int: "number", float: "number", str: "string"}


def infer(values: list[Any]) -> dict[str, Any]:
    """Schema that every value of ``values`` satisfies (one place in the tree)."""
    kinds = {type(v) for v in values if v is not None}
    nullable = any(v is None for v in values)
    if not kinds:
        return {}
    if kinds == {dict}:
        objs = [v for v in values if v is not None]
        keys = list(dict.fromkeys(k for o in objs for k in o))
        out = {
            "type": ["object", "null"] if nullable else "object",
            "properties": {k: infer([o[k] for o in objs if k in o]) for k in keys},
            "required": [k for k in keys if all(k in o for o in objs)],
            "additionalProperties": False,
        }
        return out
    if kinds == {list}:
        items = [x for v in values if v is not None for x in v]
        out = {"type": ["array", "null"] if nullable else "array"}
        if items:
            out["items"] = infer(items)
        return out
    types = sorted({SCALAR[k] for k in kinds if k in SCALAR})
    if len(types) == len(kinds) and types:
        if "number" in types:
            nullable = True  # an undefined time or ratio is null in another configuration
        return {
            "type": types + (["null"] if nullable else [])
            if len(types) > 1 or nullable
            else types[0]
        }
    return {}  # mixed containers and scalars: any value


def schema_of(results: dict[str, Any]) -> dict[str, Any]:
    """The schema document of one ``results.json``."""
    body = infer([results])
    for stage in OPTIONAL_STAGES:  # left out by --skip: null
        kind = body["properties"][stage]["type"]
        body["properties"][stage]["type"] = [kind, "null"] if isinstance(kind, str) else kind
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "ptoverify results.json",
        "description": "Every result of `ptoverify report`; regenerate with tests/results_schema.py.",
        **body,
    }


if __name__ == "__main__":
    data = json.loads(open(sys.argv[1]).read())
    print(json.dumps(schema_of(data), indent=1))
