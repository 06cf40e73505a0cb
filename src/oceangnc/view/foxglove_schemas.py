"""JSON Schemas (``jsonschema`` encoding) of the Foxglove well-known message schemas the MCAP export
writes, written here from Foxglove's published schema reference (docs.foxglove.dev, "Message
schemas"): the field names and types Foxglove and Lichtblick recognise by schema name.

Only the fields the export fills are required; every schema allows the rest of Foxglove's fields.
Times are ``{"sec": int, "nsec": int}`` (JSON encoding of Foxglove's ``time``).
"""

from __future__ import annotations

import json


def _num() -> dict:
    return {"type": "number"}


def _obj(title: str, props: dict, required: list[str] | None = None) -> dict:
    return {"type": "object", "title": title, "properties": props, "required": required or list(props)}


TIME = _obj("time", {"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0}})
DURATION = _obj("duration", {"sec": {"type": "integer"}, "nsec": {"type": "integer", "minimum": 0}})
VECTOR3 = _obj("foxglove.Vector3", {"x": _num(), "y": _num(), "z": _num()})
POINT3 = _obj("foxglove.Point3", {"x": _num(), "y": _num(), "z": _num()})
QUATERNION = _obj("foxglove.Quaternion", {"x": _num(), "y": _num(), "z": _num(), "w": _num()})
POSE = _obj("foxglove.Pose", {"position": VECTOR3, "orientation": QUATERNION})
COLOR = _obj("foxglove.Color", {"r": _num(), "g": _num(), "b": _num(), "a": _num()})


def _array(item: dict) -> dict:
    return {"type": "array", "items": item}


POSE_IN_FRAME = _obj("foxglove.PoseInFrame", {"timestamp": TIME, "frame_id": {"type": "string"}, "pose": POSE}) | {
    "description": "A timestamped pose for an object or reference frame in 3D space"
}

FRAME_TRANSFORM = _obj(
    "foxglove.FrameTransform",
    {
        "timestamp": TIME,
        "parent_frame_id": {"type": "string"},
        "child_frame_id": {"type": "string"},
        "translation": VECTOR3,
        "rotation": QUATERNION,
    },
)
FRAME_TRANSFORMS = _obj("foxglove.FrameTransforms", {"transforms": _array(FRAME_TRANSFORM)}) | {
    "description": "An array of FrameTransform messages"
}

LOCATION_FIX = _obj(
    "foxglove.LocationFix",
    {
        "timestamp": TIME,
        "frame_id": {"type": "string"},
        "latitude": _num(),
        "longitude": _num(),
        "altitude": _num(),
        "position_covariance": {"type": "array", "items": _num(), "minItems": 9, "maxItems": 9},
        "position_covariance_type": {
            "type": "integer",
            "description": "0 UNKNOWN, 1 APPROXIMATED, 2 DIAGONAL_KNOWN, 3 KNOWN",
        },
        "metadata": {
            "type": "array",
            "items": {"type": "object", "properties": {"key": {"type": "string"}, "value": {"type": "string"}}},
        },
    },
    ["latitude", "longitude", "altitude"],
) | {"description": "A navigation satellite fix for any Global Navigation Satellite System"}

CUBE = _obj("foxglove.CubePrimitive", {"pose": POSE, "size": VECTOR3, "color": COLOR})
SPHERE = _obj("foxglove.SpherePrimitive", {"pose": POSE, "size": VECTOR3, "color": COLOR})
CYLINDER = _obj(
    "foxglove.CylinderPrimitive",
    {"pose": POSE, "size": VECTOR3, "bottom_scale": _num(), "top_scale": _num(), "color": COLOR},
)
LINE = _obj(
    "foxglove.LinePrimitive",
    {
        "type": {"type": "integer", "description": "0 LINE_STRIP, 1 LINE_LOOP, 2 LINE_LIST"},
        "pose": POSE,
        "thickness": _num(),
        "scale_invariant": {"type": "boolean"},
        "points": _array(POINT3),
        "color": COLOR,
        "colors": _array(COLOR),
        "indices": _array({"type": "integer", "minimum": 0}),
    },
    ["type", "pose", "thickness", "scale_invariant", "points", "color"],
)
TRIANGLES = _obj(
    "foxglove.TriangleListPrimitive",
    {
        "pose": POSE,
        "points": _array(POINT3),
        "color": COLOR,
        "colors": _array(COLOR),
        "indices": _array({"type": "integer"}),
    },
    ["pose", "points", "color"],
)
KEY_VALUE = _obj("foxglove.KeyValuePair", {"key": {"type": "string"}, "value": {"type": "string"}})
SCENE_ENTITY = _obj(
    "foxglove.SceneEntity",
    {
        "timestamp": TIME,
        "frame_id": {"type": "string"},
        "id": {"type": "string"},
        "lifetime": DURATION,
        "frame_locked": {"type": "boolean"},
        "metadata": _array(KEY_VALUE),
        "arrows": _array({"type": "object"}),
        "cubes": _array(CUBE),
        "spheres": _array(SPHERE),
        "cylinders": _array(CYLINDER),
        "lines": _array(LINE),
        "triangles": _array(TRIANGLES),
        "texts": _array({"type": "object"}),
        "models": _array({"type": "object"}),
    },
    ["timestamp", "frame_id", "id", "lifetime", "frame_locked"],
)
SCENE_ENTITY_DELETION = _obj(
    "foxglove.SceneEntityDeletion",
    {"timestamp": TIME, "type": {"type": "integer", "description": "0 MATCHING_ID, 1 ALL"}, "id": {"type": "string"}},
)
SCENE_UPDATE = _obj(
    "foxglove.SceneUpdate", {"deletions": _array(SCENE_ENTITY_DELETION), "entities": _array(SCENE_ENTITY)}
) | {"description": "An update to the entities displayed in a 3D scene"}

#: schema name -> JSON Schema of each well-known schema the export writes
SCHEMAS = {
    "foxglove.PoseInFrame": POSE_IN_FRAME,
    "foxglove.FrameTransforms": FRAME_TRANSFORMS,
    "foxglove.LocationFix": LOCATION_FIX,
    "foxglove.SceneUpdate": SCENE_UPDATE,
}


def schema_bytes(name: str) -> bytes:
    """The JSON Schema document of the well-known schema ``name``, as MCAP schema data."""
    s = dict(SCHEMAS[name])
    s["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    return json.dumps(s, separators=(",", ":")).encode()


def signals_schema(body: str, fields: list[str]) -> dict:
    """JSON Schema of a body's scalar series message: ``timestamp`` and one number (or null: not a
    number in the log) per signal."""
    props = {"timestamp": TIME} | {f: {"type": ["number", "null"]} for f in fields}
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": f"oceangnc.Signals.{body}",
        "description": f"the logged numeric signals '{body}.*' of an oceangnc run at one log time (SI units)",
        "type": "object",
        "properties": props,
        "required": list(props),
    }
