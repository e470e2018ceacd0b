"""The handle file's JSON Schema, built from the keys the parser accepts.

Editors (VS Code's YAML extension, JetBrains IDEs) check a handle file as it is written when it
names the schema (``# yaml-language-server: $schema=...``). The schema is derived from the
parser's own key lists and the settings table, so the two cannot drift; the parser stays the
judge of what it cannot express (a vertex in two groups with different targets, indices in
range, a .def's last row).
"""
import json
from typing import Any

from ...runtime.warning_codes import CODES
from ...solver.settings import MAX_INT, SETTINGS
from .keyframes import EASINGS
from .keys import KEY_KEYS
from .selectors import SELECTOR_KEYS
from .transforms import ACTION_KEYS, ANGLE_KEYS, QUATERNION_KEYS, STATIC_ACTIONS

NUMBER = {"type": "number"}
VEC3 = {"type": "array", "items": NUMBER, "minItems": 3, "maxItems": 3}
VEC4 = {"type": "array", "items": NUMBER, "minItems": 4, "maxItems": 4}
PATH = {"type": "string", "minLength": 1, "description": "relative to the handle file"}


def _one_or_many(shape):
    return {"oneOf": [shape, {"type": "array", "items": shape, "minItems": 1}]}


def _rotate():
    angles = {k: dict(NUMBER, description="degrees" if k != "angle_rad" else "radians")
              for k in ANGLE_KEYS}
    quats = {k: dict(VEC4, description=("x, y, z, w" if k == "quaternion_xyzw"
                                        else "w, x, y, z")) for k in QUATERNION_KEYS}
    return {"type": "object", "additionalProperties": False,
            "properties": {"axis": VEC3, **angles, **quats},
            "oneOf": [{"required": ["axis"], "oneOf": [{"required": [k]} for k in ANGLE_KEYS]},
                      *({"required": [k]} for k in QUATERNION_KEYS)]}


def _selectors():
    box = {"type": "object", "additionalProperties": False, "required": ["min", "max"],
           "properties": {"min": VEC3, "max": VEC3}}
    sphere = {"type": "object", "additionalProperties": False, "required": ["center", "radius"],
              "properties": {"center": VEC3, "radius": {"type": "number", "exclusiveMinimum": 0}}}
    out = {"indices": {"type": "array", "items": {"type": "integer", "minimum": 0}},
           "box": _one_or_many(box), "sphere": _one_or_many(sphere),
           "dmat": {"type": "object", "additionalProperties": False,
                    "required": ["file", "group"],
                    "properties": {"file": PATH, "group": {"type": "integer", "minimum": 0}}},
           "sel": {"type": "object", "additionalProperties": False, "required": ["file", "status"],
                   "properties": {"file": PATH,
                                  "status": {"enum": ["fixed", "free", "handle"]}}}}
    assert set(out) == set(SELECTOR_KEYS)
    return out


def _actions():
    matrix = {"oneOf": [PATH, {"type": "array", "minItems": 4, "maxItems": 4,
                               "items": {"type": "array", "items": NUMBER,
                                         "minItems": 4, "maxItems": 4}}],
              "description": "4x4 affine matrix (last row 0 0 0 1), inline or a .def file"}
    out = {"fixed": {"type": "boolean"}, "translate": VEC3, "rotate": _rotate(),
           "pivot": VEC3, "matrix": matrix}
    assert set(out) == set(ACTION_KEYS)
    return out


def _keyframe():
    props = {"frame": {"type": "number", "minimum": 0}, "time": {"type": "number", "minimum": 0},
             "translate": VEC3, "rotate": _rotate()}
    assert set(props) == set(KEY_KEYS)
    return {"type": "object", "additionalProperties": False, "properties": props,
            "oneOf": [{"required": ["frame"]}, {"required": ["time"]}]}


def _setting(s):
    kinds: dict[str, dict[str, Any]] = {
        "float": {"type": "number"}, "int": {"type": "integer"},
        "count": {"oneOf": [{"type": "integer", "minimum": 1},
                            {"type": "string", "pattern": r"^\s*[0-9]+\s*$"}]},
        "level": {"enum": [True, False, *s.choices]},
        "codes": {"oneOf": [{"enum": list(CODES)},
                            {"type": "array", "items": {"enum": list(CODES)}}]},
        "choice": {"enum": list(s.choices)},
        "size": {"oneOf": [{"type": "integer", "minimum": 4},
                           {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1},
                           {"type": "string",
                            "pattern": r"^\s*(off|auto|\d+(\.\d*)?\s*%|0*\.\d+)\s*$"}]}}
    kind = kinds[s.kind]
    if s.minimum is not None and s.kind in ("float", "int"):
        kind["exclusiveMinimum" if s.strict else "minimum"] = s.minimum
    if s.kind in ("float", "int") and (s.maximum is not None or s.kind == "int"):
        kind["maximum"] = s.maximum if s.maximum is not None else MAX_INT
    if s.default is None:
        kind = {"oneOf": [kind, {"type": "null"}]}
    default = list(s.default) if isinstance(s.default, tuple) else s.default
    return dict(kind, description=s.help, **({"default": default} if default is not None
                                             else {}))


def handle_schema() -> dict:
    """The JSON Schema (draft 2020-12) of a YAML/JSON handle file."""
    group = {"type": "object", "additionalProperties": False,
             "properties": {**_selectors(), **_actions(),
                            "keyframes": {"type": "array", "items": _keyframe(), "minItems": 1},
                            "easing": {"enum": sorted(EASINGS)}},
             "anyOf": [{"required": [k]} for k in SELECTOR_KEYS],
             # keyframes hold the motion: no static action beside them (the parser's rule)
             "if": {"required": ["keyframes"]},
             "then": {"not": {"anyOf": [{"required": [k]} for k in STATIC_ACTIONS]}}}
    region = {"type": "object", "additionalProperties": False, "properties": _selectors(),
              "anyOf": [{"required": [k]} for k in SELECTOR_KEYS]}
    return {"$schema": "https://json-schema.org/draft/2020-12/schema",
            "$id": "https://srarap.readthedocs.io/handles.schema.json",
            "title": "srarap handle file",
            "description": "Which vertices are held (groups) and where they go.",
            "type": "object", "additionalProperties": False, "required": ["groups"],
            "properties": {"groups": {"type": "object", "minProperties": 1,
                                      "additionalProperties": group},
                           "region": region,
                           "solver": {"type": "object", "additionalProperties": False,
                                      "properties": {s.name: _setting(s) for s in SETTINGS}}}}


def schema_text() -> str:
    """The schema as the file the docs publish (``docs/handles.schema.json``)."""
    return json.dumps(handle_schema(), indent=2) + "\n"
