"""The OpenAPI schema's last touch: answers carry every field their serializer has.

drf-spectacular marks a field required only if a request must send it, so a field with a
default (a label's ``hotkey``) would look optional in an answer, and the front end's
generated types would make it ``hotkey?: …``. A DRF serializer always writes all its
fields, so in the answer components (requests are split into ``…Request`` components by
``COMPONENT_SPLIT_REQUEST``) every property is required; null stays a separate matter.
"""


def answers_have_every_field(result, generator, request, public):
    for name, component in result.get("components", {}).get("schemas", {}).items():
        if name.endswith("Request") or "properties" not in component:
            continue
        component["required"] = sorted(component["properties"])
    return result
